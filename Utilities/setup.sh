#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
#
# The README's two Quick start commands:
#   Utilities/setup.sh demo [demo options]   set up, build, run the main demo (Examples/Python/deform_mesh.py)
#   Utilities/setup.sh test [ctest options]  set up, build (the ParaView plugin too), run every test through ctest
# and the sanitizer run that CI adds (docs/testing.md, "Tests"):
#   Utilities/setup.sh sanitize [ctest options]  the same set-up, then every test of an ASan + UBSan build
# Set-up = install the missing Debian 12 packages, fetch the real meshes, configure once, build. Every step is
# skipped when its result is already there, so a second run only costs a no-op ninja.
#
# Environment: VOXELFFD_BUILD_DIR (default <repository>/build, or <repository>/build-sanitize for sanitize).
set -euo pipefail

usage() {
  echo "usage:" >&2
  sed -n '5,6s/^#//p;8s/^#//p' "$0" >&2 # the command lines of the header above
  exit 2
}

[[ $# -ge 1 ]] || usage
action=$1
shift
[[ $action == demo || $action == test || $action == sanitize ]] || usage

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
if [[ $action == sanitize ]]; then
  build=${VOXELFFD_BUILD_DIR:-$root/build-sanitize}
  # No CUDA backend here: nvcc's device code is not instrumented, and the release build compiles and tests it.
  configure_options=(-DCMAKE_BUILD_TYPE=Debug "-DVOXELFFD_SANITIZE=address;undefined" -DVOXELFFD_ENABLE_CUDA=OFF)
else
  build=${VOXELFFD_BUILD_DIR:-$root/build}
  configure_options=(-DCMAKE_BUILD_TYPE=Release)
fi
mesh_dir=$root/Testing/Data/Meshes
# Debian's interpreter: it has VTK's Python (vtkmodules) and numpy, which another python3 on PATH may lack.
python=/usr/bin/python3

step() { printf '\n==> %s\n' "$*"; }

# Root runs apt directly (CI containers have no sudo); anyone else goes through sudo.
as_root() {
  if [[ $(id -u) -eq 0 ]]; then
    "$@"
  else
    sudo "$@"
  fi
}

# --- 1. Debian packages ---------------------------------------------------------------------------------------
packages=(build-essential cmake ninja-build libvtk9-dev python3-vtk9 libopenvdb-dev libopenvdb-tools
  libboost-iostreams-dev libeigen3-dev libqhull-dev libgtest-dev xvfb xauth libgl1-mesa-dri python3-numpy
  libinsighttoolkit5-dev openmpi-bin python3-mpi4py) # ITK: tests only; Open MPI and mpi4py: the MPI tests
if [[ $action == test ]]; then
  packages+=(paraview paraview-dev) # the plugin and its tests (ParaView/, Testing/ParaView)
  # vtkffd.torch and vtkffd.sparse are optional for users; their tests (Python.test_torch, test_weight_matrix) and
  # the shape-optimisation example need them: PyTorch 1.13 CPU (48 packages, 70 MB, about 10 s to install)
  packages+=(python3-torch python3-scipy)
fi
step "Debian packages"
missing=()
for package in "${packages[@]}"; do
  if [[ $(dpkg-query -W -f='${db:Status-Status}' "$package" 2>/dev/null || true) != installed ]]; then
    missing+=("$package")
  fi
done
if [[ ${#missing[@]} -gt 0 ]]; then
  echo "installing: ${missing[*]}"
  as_root apt-get update
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends "${missing[@]}"
else
  echo "all ${#packages[@]} packages are installed"
fi

# --- 2. Real meshes -------------------------------------------------------------------------------------------
# CGAL's sample meshes (OFF) come with Debian's libcgal-demo package; VTK 9.1 reads no OFF, so they are
# converted to VTK XML PolyData. They are git-ignored: fetched here, never committed.
meshes=(bear elephant armadillo camel cow)
step "Meshes in ${mesh_dir#"$root"/}"
missing=()
for mesh in "${meshes[@]}"; do
  [[ -s $mesh_dir/$mesh.vtp ]] || missing+=("$mesh")
done
if [[ ${#missing[@]} -gt 0 ]]; then
  echo "fetching libcgal-demo for: ${missing[*]}"
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT # on failure; removed below on success
  # apt downloads as the unprivileged _apt user when run as root; let it write here (else apt warns and
  # downloads unsandboxed).
  if [[ $(id -u) -eq 0 ]] && id _apt >/dev/null 2>&1; then
    chown _apt "$work"
  fi
  # A fresh system may have no package lists at all (apt-get download then finds nothing).
  if ! apt-cache show libcgal-demo >/dev/null 2>&1; then
    as_root apt-get update
  fi
  (cd "$work" && apt-get download libcgal-demo)
  dpkg-deb --fsys-tarfile "$work"/libcgal-demo_*.deb | tar -x -C "$work" ./usr/share/doc/libcgal-dev/data.tar.gz
  members=()
  for mesh in "${missing[@]}"; do members+=("data/meshes/$mesh.off"); done
  tar -xzf "$work/usr/share/doc/libcgal-dev/data.tar.gz" -C "$work" "${members[@]}"
  mkdir -p "$mesh_dir"
  for mesh in "${missing[@]}"; do
    # Convert beside the target and rename, so an interrupted run leaves no half-written mesh behind.
    "$python" "$root/Utilities/off_to_vtp.py" "$work/data/meshes/$mesh.off" "$mesh_dir/.$mesh.vtp.tmp"
    mv "$mesh_dir/.$mesh.vtp.tmp" "$mesh_dir/$mesh.vtp"
    echo "  $mesh.vtp"
  done
  rm -rf "$work"
else
  echo "all ${#meshes[@]} meshes are there"
fi

# --- 3. Configure and build -----------------------------------------------------------------------------------
step "Build in ${build}"
# Configure only when there is no build system yet (also after a configure that failed half-way); Ninja re-runs
# CMake by itself when a CMakeLists.txt changed.
if [[ ! -f $build/build.ninja ]]; then
  cmake -G Ninja -S "$root" -B "$build" -DPython3_EXECUTABLE="$python" "${configure_options[@]}"
fi
# The ParaView plugin (test only) has a build tree of its own in $build/paraview, against ParaView's VTK, linking
# the evaluation libraries of $build; the main build then learns the plugin's test settings from it
# (Testing/ParaView), once.
if [[ $action == test ]]; then
  step "ParaView plugin in ${build}/paraview"
  "$root/Utilities/paraview-prefix.sh" "$build/paraview-prefix"
  if [[ ! -f $build/paraview/build.ninja ]]; then
    cmake -G Ninja -S "$root/ParaView" -B "$build/paraview" -DCMAKE_BUILD_TYPE=Release \
      "-DParaView_DIR=$build/paraview-prefix/usr/lib/$(gcc -print-multiarch)/cmake/paraview-5.11" \
      "-DVOXELFFD_EVALUATION_TREE=$build"
  fi
  if ! grep -q "^VOXELFFD_PARAVIEW_PLUGIN_TREE:PATH=$build/paraview\$" "$build/CMakeCache.txt"; then
    cmake "$build" "-DVOXELFFD_PARAVIEW_PLUGIN_TREE=$build/paraview"
  fi
fi
cmake --build "$build"
if [[ $action == test ]]; then
  cmake --build "$build/paraview"
fi

# --- 4. Run ---------------------------------------------------------------------------------------------------
case $action in
  demo)
    step "Demo: Examples/Python/deform_mesh.py"
    # Rendering needs an X display (Debian's VTK is GLX-only): the caller's, or a virtual one from Xvfb.
    PYTHONPATH="$build/lib/python3/dist-packages${PYTHONPATH:+:$PYTHONPATH}" \
      "$root/Utilities/with-display.sh" "$python" "$root/Examples/Python/deform_mesh.py" \
      --output-dir "$build/demo" "$@"
    ;;
  test)
    step "Tests: ctest"
    # One X display for the whole suite (the caller's, or one virtual server): the tests that render use it. As
    # many tests at a time as there are cores: no test depends on timing or on another's files.
    "$root/Utilities/with-display.sh" ctest --test-dir "$build" --output-on-failure -j "$(nproc)" "$@"
    ;;
  sanitize)
    step "Tests under AddressSanitizer and UndefinedBehaviorSanitizer: ctest"
    # Any finding fails its test (halt_on_error; the build has -fno-sanitize-recover). Leaks of third-party
    # code are suppressed by Utilities/sanitizers/lsan.supp, each with its reason.
    sanitizers=$root/Utilities/sanitizers
    ASAN_OPTIONS=halt_on_error=1:detect_leaks=1:strict_string_checks=1:check_initialization_order=1 \
      UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 \
      LSAN_OPTIONS=suppressions=$sanitizers/lsan.supp:print_suppressions=0 \
      "$root/Utilities/with-display.sh" ctest --test-dir "$build" --output-on-failure -j "$(nproc)" "$@"
    ;;
esac
