#!/usr/bin/env bash
# Installs dyncull from a build tree into a temporary prefix and builds every example in
# examples/ against that installed copy, as a game would, then runs them: a
# broken install, a missing header or a dependency the runtime component should not need
# fails here. Usage: examples_against_install.sh BUILD_DIR SOURCE_DIR WORK_DIR
set -euo pipefail
build=$1 src=$2 work=$3
rm -rf "$work"
mkdir -p "$work"
prefix=$work/prefix

cmake --install "$build" --prefix "$prefix" >"$work/install.log"
# The runtime component must not bring GLFW, X11 or the loaders' libraries with it.
if grep -Eq "glfw|X11|tinygltf|TinyGLTF|nlohmann" "$prefix"/lib*/cmake/dyncull/dyncull-runtime-targets*.cmake; then
  echo "FAIL: the runtime component's targets refer to window or loader libraries" >&2
  exit 1
fi

# CMake: find_package(dyncull COMPONENTS runtime).
cmake -S "$src/examples/headless" -B "$work/headless" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release \
  >"$work/configure.log"
cmake --build "$work/headless" -j2 >"$work/build.log"
"$work/headless/headless_game" --frames 8 --cull full --check --screenshot "$work/headless_full.png"

# The windowed game (its own GLFW window, textures and shader); run where a display can be
# made (Xvfb), else only built.
cmake -S "$src/examples/glfw_game" -B "$work/glfw_game" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release \
  >"$work/configure_glfw.log"
cmake --build "$work/glfw_game" -j2 >"$work/build_glfw.log"
if command -v xvfb-run >/dev/null; then
  xvfb-run -a "$work/glfw_game/glfw_game" --frames 30 --check --screenshot "$work/glfw_game.png"
  [[ -s "$work/glfw_game.png" ]] || { echo "FAIL: glfw_game wrote no screenshot" >&2; exit 1; }
else
  echo "glfw_game: built; not run (no xvfb-run)"
fi

# pkg-config: the same program built with the flags dyncull.pc gives.
PKG_CONFIG_PATH="$prefix/lib/pkgconfig:$prefix/lib/$(gcc -print-multiarch)/pkgconfig" \
  c++ -std=c++20 -O1 "$src/examples/headless/main.cpp" -o "$work/headless_pc" \
  $(PKG_CONFIG_PATH="$prefix/lib/pkgconfig:$prefix/lib/$(gcc -print-multiarch)/pkgconfig" pkg-config --cflags --libs dyncull stb)
"$work/headless_pc" --frames 4 --cull queries --check --screenshot "$work/headless_pc.png"
# The loaders component resolves on its own (its libraries come with it); an unknown one fails.
mkdir -p "$work/components"
cat >"$work/components/CMakeLists.txt" <<'CMAKE'
cmake_minimum_required(VERSION 3.25)
project(components LANGUAGES CXX)
find_package(dyncull REQUIRED COMPONENTS runtime loaders)
if(NOT TARGET dyncull::loaders OR NOT TARGET dyncull::engine)
  message(FATAL_ERROR "components: targets missing")
endif()
find_package(dyncull QUIET COMPONENTS viewer)
if(dyncull_FOUND)
  message(FATAL_ERROR "components: an unknown component was accepted")
endif()
CMAKE
cmake -S "$work/components" -B "$work/components/build" -DCMAKE_PREFIX_PATH="$prefix" >"$work/components.log"
echo "examples: built against $prefix and run"
