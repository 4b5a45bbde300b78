#!/usr/bin/env bash
# Installs the build into a temporary prefix, then compiles the README's C
# example twice, with find_package(meshfmm) and with pkg-config, runs both and
# checks the distances on the unit square: 0, 1, 1, sqrt(2).
# Usage: run.sh SOURCE_DIR BUILD_DIR
set -euo pipefail
src=$1 build=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cmake --install "$build" --prefix "$tmp/prefix" >/dev/null
mkdir -p "$tmp/consumer"
cp "$src/tests/consumer/CMakeLists.txt" "$tmp/consumer/"
# the first ```c block of the README
awk '/^```c$/ {on = 1; next} /^```$/ && on {exit} on' "$src/README.md" > "$tmp/consumer/readme_example.c"
test -s "$tmp/consumer/readme_example.c"
cmake -S "$tmp/consumer" -B "$tmp/consumer/build" -DCMAKE_PREFIX_PATH="$tmp/prefix" >/dev/null
cmake --build "$tmp/consumer/build" >/dev/null
libdir=$(dirname "$(find "$tmp/prefix" -name 'libmeshfmm.so*' | head -1)")
expected="0 0.000000000000
1 1.000000000000
2 1.000000000000
3 1.414213562373"
out=$(LD_LIBRARY_PATH="$libdir" "$tmp/consumer/build/readme_example")
[ "$out" = "$expected" ] || { echo "find_package build printed:"; echo "$out"; exit 1; }
export PKG_CONFIG_PATH="$libdir/pkgconfig"
cc -std=c99 -Wall -Wextra -Werror "$tmp/consumer/readme_example.c" -o "$tmp/pc_example" \
   $(pkg-config --cflags --libs meshfmm)
out=$(LD_LIBRARY_PATH="$libdir" "$tmp/pc_example")
[ "$out" = "$expected" ] || { echo "pkg-config build printed:"; echo "$out"; exit 1; }
echo "README example: find_package and pkg-config builds print the exact distances"
