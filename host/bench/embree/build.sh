#!/bin/sh
# Builds hemi-embree, the Embree 3 side of `hemi bench scale --embree` (not part of CI).
# Needs Debian's libembree-dev (`apt-get install libembree-dev g++`).
# usage: host/bench/embree/build.sh [OUT]   (default: target/hemi-embree)
set -eu
here=$(dirname "$0")
out=${1:-target/hemi-embree}
mkdir -p "$(dirname "$out")"
g++ -std=c++17 -O2 -pthread -o "$out" "$here/hemi_embree.cpp" -lembree3
echo "built $out"
