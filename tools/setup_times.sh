#!/usr/bin/env bash
# Times the README's two fresh-clone commands as a new user meets them: a clone of this
# repository's committed HEAD in a temporary directory with nothing beside it, no
# SPDCAM_DATA, and an empty target directory (the clone's own target/). Crates already in
# cargo's download cache are not downloaded again; a first-ever build also downloads them.
#
#   bash tools/setup_times.sh
#
# Prints the wall time of each command; the README's "Set-up times" line quotes them.
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
unset SPDCAM_DATA CARGO_TARGET_DIR
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
git clone --quiet "$repo" "$work/spdcam"
cd "$work/spdcam"
test ! -e ../shared

# The README's first block, line by line.
mapfile -t commands < <(python3 - README.md <<'EOF'
import re, sys
text = open(sys.argv[1], encoding="utf-8").read()
first = re.search(r"^```sh\n(.*?)^```", text, flags=re.S | re.M).group(1)
print("\n".join(l for l in first.splitlines() if l.strip()))
EOF
)
echo "machine: $(nproc) cores, $(uname -m); $(cargo --version)"
for command in "${commands[@]}"; do
    start=$(date +%s)
    bash -euo pipefail -c "$command" >"$work/log" 2>&1 || {
        tail -n 30 "$work/log" >&2
        echo "error: '$command' failed" >&2
        exit 1
    }
    seconds=$(($(date +%s) - start))
    printf '%-60s %d min %02d s\n' "$command" $((seconds / 60)) $((seconds % 60))
done
