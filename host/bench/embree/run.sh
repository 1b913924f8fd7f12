#!/bin/sh
# Regenerates the "Pass 1 at scale" tables and docs/figures/scale-hemisphere.svg of
# docs/PERFORMANCE.md: builds the Embree program, then runs `hemi bench scale`, which measures
# hemi's pass 1 and, right after it on the same rays, Embree's, scene by scene (one run).
# Needs Debian's libembree-dev and g++; not part of CI.
set -eu
cd "$(dirname "$0")/../../.."
host/bench/embree/build.sh target/hemi-embree
cargo build --release -p hemi-cli
hemi=target/release/hemi
$hemi bench scale --cuts 1,2,4,8,16 --rooms 10000 --embree target/hemi-embree --svg-dir docs/figures
$hemi bench scale --cuts '' --rooms 50000 --circles 32 --embree target/hemi-embree
