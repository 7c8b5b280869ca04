#!/usr/bin/env bash
# The JS package's test as a user meets it: packs examples/wasm/package with `npm pack` (after
# package/build.sh), installs the tarball into a fresh consumer project, runs test.mjs there
# (`import { Probe } from "sphere-quadrature"`) against the host reference, and type-checks
# types.ts with tsc (from examples/wasm/node_modules: run `npm ci` in examples/wasm first).
#
#   cargo eval js_package_reference > reference.txt
#   examples/wasm/package/test/run.sh reference.txt [WORKDIR]
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
reference="$(cd "$(dirname "$1")" && pwd)/$(basename "$1")"
work="${2:-$(mktemp -d)}"
mkdir -p "$work"
work="$(cd "$work" && pwd)"
rm -rf "$work/consumer" "$work"/sphere-quadrature-*.tgz
(cd "$here/.." && npm pack --silent --pack-destination "$work" > /dev/null)
tarball=$(ls "$work"/sphere-quadrature-*.tgz)
echo "packed $(basename "$tarball") ($(wc -c < "$tarball") bytes):"
tar -tzvf "$tarball" | awk '{print "  " $3 " " $6}'
mkdir "$work/consumer"
cp "$here/test.mjs" "$here/bench.mjs" "$here/types.ts" "$here/tsconfig.json" "$work/consumer/"
printf '{ "name": "consumer", "private": true, "type": "module" }\n' > "$work/consumer/package.json"
(cd "$work/consumer" && npm install --offline --no-audit --no-fund --silent "$tarball")
(cd "$work/consumer" && node test.mjs "$reference")
tsc="$here/../../node_modules/.bin/tsc"
[ -x "$tsc" ] || { echo "no tsc at $tsc: run npm ci in examples/wasm"; exit 1; }
"$tsc" -p "$work/consumer/tsconfig.json"
echo "types.ts type-checks against the installed package (tsc $("$tsc" --version))"
