#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# The image tests on the GPU machine, which has NVIDIA's EGL but no X display: every test of vtkFFDRenderingTests
# (or those named) through vtkFFDEGLRenderWindow, against the baselines of Testing/Data/Baseline; the driver
# prints GL_RENDERER first. The interop tests must find the device path there (VOXELFFD_EXPECT_INTEROP=1: the
# CUDA device writes the vertex buffers). Run from the repository's root with the bundle of
# ../shared/tools/gpu-bundle.sh:
#   bash Utilities/gpu-rendering.sh [TestName ...]          (device tool: carry [".gpu"])
#   bash Utilities/gpu-rendering.sh --benchmark [ARGS ...]  (BenchmarkFFDInterop, through the same window)
set -u
root=$(cd "$(dirname "$0")/.." && pwd)
out=${OUT:-/tmp}
vendor=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
[[ -f $vendor ]] && export __EGL_VENDOR_LIBRARY_FILENAMES=$vendor
export VOXELFFD_RENDER_WINDOW=egl VOXELFFD_EXPECT_INTEROP=1
if [[ ${1:-} == --benchmark ]]; then
  shift
  exec bash "$root/.gpu/run.sh" BenchmarkFFDInterop "$@"
fi
tests=("$@")
if [[ ${#tests[@]} -eq 0 ]]; then
  mapfile -t tests < <(sed -n 's/^  \(TestFFD[A-Za-z]*\)\.cxx)\{0,1\}$/\1/p' "$root/Testing/Rendering/CMakeLists.txt")
fi
rc=0
for t in "${tests[@]}"; do
  bash "$root/.gpu/run.sh" vtkFFDRenderingTests "$t" -V "$root/Testing/Data/Baseline/$t.png" -T "$out" \
    >"$out/$t.log" 2>&1
  r=$?
  [[ $r == 0 ]] || rc=$r
  echo "$t: exit $r; $(grep -m1 'GL_RENDERER' "$out/$t.log")"
done
exit $rc
