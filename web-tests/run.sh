#!/usr/bin/env bash
# End-to-end tests of `spdcam serve` in headless Chromium: installs what is missing
# (Debian's chromium, playwright-core from npm), builds spdcam, starts the server on a free
# loopback port, and runs the browser tests against the CLI's own estimate of the example;
# then opens the CLI's HTML report of the example offline from its file, and prints the
# reports to PDF on A4 and Letter (pdfinfo counts the pages: poppler-utils, installed when
# missing). Before them, a
# load check: 20 concurrent uploads of a 12-megapixel photo (web-tests/load.mjs).
# Screenshots and the report go to $SPDCAM_WEB_ARTEFACTS (default: <target dir>/web-tests).
# Ends with "N passed, N failed" and a non-zero status when a test failed.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
repo="$(dirname "$here")"
target="${CARGO_TARGET_DIR:-$repo/target}"
artefacts="${SPDCAM_WEB_ARTEFACTS:-$target/web-tests}"
# The page's example (a ColorChecker 24 under a white LED), so that the page's "Try the
# example photo" and the CLI's estimate of PHOTO are one photo.
photo="$repo/examples/cc24-led.jpg"
truth="$repo/examples/cc24-led.truth.csv"

if ! [ -x /usr/bin/chromium ]; then
    if [ "$(id -u)" != 0 ]; then
        echo "error: /usr/bin/chromium is missing; install it as root: apt-get install -y chromium" >&2
        echo "0 passed, 1 failed"
        exit 1
    fi
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null
fi
if ! command -v pdfinfo >/dev/null; then
    if [ "$(id -u)" != 0 ]; then
        echo "error: pdfinfo is missing; install it as root: apt-get install -y poppler-utils" >&2
        echo "0 passed, 1 failed"
        exit 1
    fi
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq poppler-utils >/dev/null
fi
if ! [ -f "$here/node_modules/playwright-core/package.json" ]; then
    (cd "$here" && npm ci --no-audit --no-fund)
fi

cargo build --release --manifest-path "$repo/Cargo.toml"
bin="$target/release/spdcam"
mkdir -p "$artefacts"
work="$(mktemp -d)"
server=""
cleanup() {
    if [ -n "$server" ]; then kill "$server" 2>/dev/null || true; fi
    rm -rf "$work"
}
trap cleanup EXIT

"$bin" estimate --json "$photo" >"$work/expected.json"
"$bin" estimate "$photo" -o "$work/expected.csv" >/dev/null
"$bin" estimate "$photo" --report "$artefacts/report.html" >/dev/null
"$bin" serve --port 0 >"$work/serve.log" 2>&1 &
server=$!
url=""
for _ in $(seq 300); do
    url="$(grep -o 'http://[^ ]*' "$work/serve.log" | head -n 1 || true)"
    [ -n "$url" ] && break
    if ! kill -0 "$server" 2>/dev/null; then break; fi
    sleep 0.1
done
if [ -z "$url" ]; then
    echo "error: spdcam serve did not start:" >&2
    cat "$work/serve.log" >&2
    echo "0 passed, 1 failed"
    exit 1
fi
echo "server: $url"
# Load: 20 concurrent uploads of a 12-megapixel photo, every answer checked, the server's
# peak memory printed.
"$bin" render --spd A --scene 4000x3000 -o "$work/12mp.jpg" >/dev/null
node "$here/load.mjs" "$url" "$work/12mp.jpg" 20 "$server"
node "$here/e2e.mjs" "$url" "$work/expected.json" "$photo" "$truth" "$artefacts" "$artefacts/report.html" "$work/expected.csv"
