#!/usr/bin/env bash
# Installs missing dependencies, then configures and builds mcrewave in Release
# into build/ (or $MCREWAVE_BUILD_DIR), benchmarks included unless the arguments
# (extra cmake options) say -DMCREWAVE_BUILD_BENCHMARKS=OFF.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${MCREWAVE_BUILD_DIR:-$root/build}"

bash "$root/scripts/install_dependencies.sh"
cmake -S "$root" -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DMCREWAVE_BUILD_BENCHMARKS=ON "$@"
cmake --build "$build_dir" -j "$(nproc)"
