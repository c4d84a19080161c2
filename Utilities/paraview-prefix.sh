#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
#
# Utilities/paraview-prefix.sh PREFIX
#
# Makes PREFIX a stand-in for /usr in which Debian 12's ParaView 5.11 can be built against, without touching the
# system. Debian's paraview-dev is incomplete without python3-paraview: its CMake package checks files that
# python3-paraview installs (pvpython, ParaView's Python modules, the wrap-hierarchy files that client-server
# wrapping reads). python3-paraview cannot be installed beside python3-vtk9, which this project's Python needs
# (both ship `vtkmodules`), so it is unpacked into PREFIX/extract instead, and PREFIX/usr mirrors /usr with
# symbolic links plus those files. ParaView's CMake package finds its prefix from its own location, so it is
# copied into PREFIX/usr; then -DParaView_DIR=PREFIX/usr/lib/<triplet>/cmake/paraview-5.11 builds plugins, and
# pvbatch or pvpython run paraview.simple with PYTHONPATH=PREFIX/extract/usr/lib/python3/dist-packages.
#
# Idempotent: a complete prefix (the stamp file) is left as it is. Needs the paraview and paraview-dev packages.
set -euo pipefail

[[ $# -eq 1 ]] || { echo "usage: $0 PREFIX" >&2; exit 2; }
prefix=$(realpath -m "$1")
stamp=$prefix/.complete
[[ -f $stamp ]] && exit 0

triplet=$(gcc -print-multiarch)
paraview_cmake=/usr/lib/$triplet/cmake/paraview-5.11
[[ -d $paraview_cmake ]] || { echo "$0: $paraview_cmake is missing: install paraview-dev" >&2; exit 1; }

if ! apt-cache show python3-paraview >/dev/null 2>&1; then
  echo "$0: apt knows no python3-paraview: run apt-get update" >&2
  exit 1
fi

rm -rf "$prefix"
mkdir -p "$prefix/download" "$prefix/extract"
# apt downloads as the unprivileged _apt user when run as root: let it write there.
if [[ $(id -u) -eq 0 ]] && id _apt >/dev/null 2>&1; then
  chown _apt "$prefix/download"
fi
(cd "$prefix/download" && apt-get download python3-paraview)
dpkg-deb -x "$prefix"/download/python3-paraview_*.deb "$prefix/extract"
rm -rf "$prefix/download"

usr=$prefix/usr
mkdir -p "$usr/bin" "$usr/lib/$triplet/cmake" "$usr/lib/python3"
ln -s /usr/include "$usr/include"
ln -s /usr/share "$usr/share"
ln -s "$prefix/extract/usr/lib/python3/dist-packages" "$usr/lib/python3/dist-packages"
ln -s /usr/bin/* "$usr/bin/"
ln -s "$prefix"/extract/usr/bin/* "$usr/bin/" # pvpython
for entry in /usr/lib/"$triplet"/*; do
  case ${entry##*/} in
    cmake | vtk) ;; # below
    *) ln -s "$entry" "$usr/lib/$triplet/" ;;
  esac
done
ln -s "$prefix/extract/usr/lib/$triplet/vtk" "$usr/lib/$triplet/vtk" # ParaView's wrap-hierarchy files
for entry in /usr/lib/"$triplet"/cmake/*; do
  [[ ${entry##*/} == paraview-5.11 ]] || ln -s "$entry" "$usr/lib/$triplet/cmake/"
done
cp -r "$paraview_cmake" "$usr/lib/$triplet/cmake/"
touch "$stamp"
