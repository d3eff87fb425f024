#!/usr/bin/env bash
# Installs the Debian packages mcrewave needs, only those that are missing, and the
# packages named as arguments (a study script's own, e.g. python3-numpy).
# Runs as root (or through sudo when available); never prompts.
set -euo pipefail

packages=(
  cmake g++ make
  libeigen3-dev libnlopt-cxx-dev libceres-dev libyaml-cpp-dev libspdlog-dev
  libcli11-dev libgtest-dev libgmock-dev libbenchmark-dev gnuplot-nox
  clang libclang-rt-14-dev
  python3-dev python3-numpy python3-scipy pybind11-dev
  "$@"
)

missing=()
for package in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "mcrewave: installing missing Debian packages: ${missing[*]}"
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then
    sudo_cmd=(sudo)
  else
    echo "mcrewave: missing packages (${missing[*]}) and not root; install them first" >&2
    exit 1
  fi
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
