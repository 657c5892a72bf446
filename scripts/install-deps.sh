#!/usr/bin/env bash
# Install what Aloft needs from Debian 12's packages, idempotently: nothing is downloaded when every
# package is already there. Usage: scripts/install-deps.sh [extra-package ...]
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev nlohmann-json3-dev libcli11-dev
  libgtest-dev libbenchmark-dev
  libccd-dev                                   # collisions: GJK/EPA for convex pieces
  libsdl2-dev sox                              # microphone capture (SDL2); sox makes test signals
  libglfw3-dev libimgui-dev libstb-dev         # the viewer: window, panel, PNG writing
  libgl-dev libegl-dev libgl1-mesa-dri         # OpenGL (Mesa's llvmpipe) and headless EGL
  xvfb xauth ffmpeg                            # viewer tests under a virtual display; video encoding
  "$@"
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  exit 0
fi

echo "aloft: installing ${missing[*]}" >&2
sudo=""
if [[ $(id -u) -ne 0 ]]; then sudo="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
