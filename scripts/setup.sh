#!/usr/bin/env bash
# Installs what is missing (Debian 12 packages; as root or with sudo), fetches the
# public-domain npm `bunny` mesh into ./assets when no full-resolution bunny is there,
# then configures and builds dyncull into ./build. Idempotent: a second run only
# rebuilds what changed. Extra arguments are passed to the CMake configure step.
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
  build-essential cmake pkg-config git
  libglfw3-dev libglm-dev libegl-dev libgl-dev libepoxy-dev libegl-mesa0 libgl1-mesa-dri
  libtinygltf-dev nlohmann-json3-dev libstb-dev libcli11-dev libmeshoptimizer-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  xvfb xauth gnuplot-nox
)
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# Node.js and npm fetch the public-domain bunny; any installed node will do.
command -v node >/dev/null || missing+=(nodejs)
command -v npm >/dev/null || missing+=(npm)
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  SUDO=""
  if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# Bunny mesh: the full-resolution Stanford bunny if the user put it in ./assets,
# otherwise the npm registry's public-domain low-resolution bunny, converted to PLY.
mkdir -p assets
if [[ ! -f assets/bun_zipper.ply && ! -f assets/bunny_npm.ply ]]; then
  echo "setup: fetching the public-domain bunny from the npm registry"
  tmp=$(mktemp -d)
  (cd "$tmp" && npm install --silent --no-audit --no-fund bunny@1.0.1 >/dev/null)
  node scripts/bunny_npm_to_ply.js "$tmp/node_modules/bunny" assets/bunny_npm.ply
  rm -rf "$tmp"
fi

BUILD_DIR=${DYNCULL_BUILD_DIR:-build}
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=RelWithDebInfo "$@" >/dev/null
cmake --build "$BUILD_DIR" -j"$(nproc)"
echo "setup: built $BUILD_DIR/bin/dyncull"
