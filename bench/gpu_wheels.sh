#!/usr/bin/env bash
# Wheels that the lent GPU machine's image lacks for `import sph_core.simulation` and the tests
# (its image has numpy, numba, numba-cuda, scipy, pytest; docs/developer/gpu.md), saved to .whl/
# of the repo for bench/gpu_check.sh (carry ".whl"). Python 3.12, x86-64, ~5 MB.
set -eu
cd "$(dirname "$0")/.."
grep -qx "/.whl/" "$(git rev-parse --git-common-dir)/info/exclude" 2>/dev/null \
    || echo "/.whl/" >> "$(git rev-parse --git-common-dir)/info/exclude"
mkdir -p .whl
for pkg in pydantic==2.14.4 pydantic_core==2.50.5 annotated-types==0.8.0 typing-inspection==0.4.5 \
           typing_extensions==4.16.0 pyevtk==1.7.0 pyamg==5.4.1 raschii==2.0.0; do
    python3 -m pip download -q --no-deps --only-binary=:all: --python-version 3.12 --implementation cp \
        --platform manylinux_2_28_x86_64 --platform manylinux_2_27_x86_64 \
        --platform manylinux_2_17_x86_64 --platform manylinux2014_x86_64 \
        --platform manylinux1_x86_64 -d .whl "$pkg" 2>&1 | grep -v "is ignored" || true
done
ls -la .whl && du -sh .whl
