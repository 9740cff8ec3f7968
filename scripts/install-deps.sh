#!/usr/bin/env bash
# Installs every Debian package Cradle needs; skips the ones already present (idempotent).
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config clang-format
  libmujoco-dev libmujoco-samples
  libosmesa6-dev libegl-dev libgl-dev libegl-mesa0 libgl1-mesa-dri
  libyaml-cpp-dev nlohmann-json3-dev libcli11-dev libstb-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  zlib1g-dev
  libtorch-dev libopenblas0-pthread
  libavcodec-dev libavformat-dev libswscale-dev libavutil-dev ffmpeg
  python3 python3-numpy python3-dev pybind11-dev python3-pytest
  python3-pip python3-venv python3-setuptools python3-wheel  # pip install . (offline)
  ccache
  libbox2d-dev libcairo2-dev libzip-dev libeigen3-dev
  python3-matplotlib python3-scipy python3-pandas
  slurm-wlm munge
  python3-torch  # only for the side-by-side benchmark bench/sami_update_torch.py
  libgloo-dev
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi
"${sudo_cmd[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
