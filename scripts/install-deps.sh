#!/usr/bin/env bash
# Installs primseg's build and test dependencies from Debian's packages (root; skipped when
# everything is already present).
set -euo pipefail
packages=(build-essential cmake ninja-build clang clang-tidy libclang-rt-14-dev libeigen3-dev
          libcli11-dev nlohmann-json3-dev libgtest-dev libgmock-dev libbenchmark-dev libcgal-demo
          python3-dev python3-numpy pybind11-dev python3-pybind11 python3-pytest python3-scipy
          python3-mypy
          chromium)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# The web viewer's build and tests: node and npm, whichever package provides them.
command -v npm >/dev/null || missing+=(nodejs npm)
if ((${#missing[@]})); then
  if [[ $(id -u) -ne 0 ]]; then
    echo "primseg needs: ${missing[*]} (run as root, or: sudo apt-get install ${missing[*]})" >&2
    exit 1
  fi
  echo "installing: ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
