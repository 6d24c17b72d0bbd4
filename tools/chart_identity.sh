#!/usr/bin/env bash
# Measures the chart identity test (docs/chart-identity.md): makes scene photos of both
# charts under several lights and cameras, virtual dataset rows with every randomisation,
# and runs the measuring example over them, the real measured feature rows and the images
# with no chart it makes itself. Prints the acceptance table; every item's statistics go to
# chart-identity-items.tsv in the working folder.
#
#   bash tools/chart_identity.sh DATA_DIR [WORK_DIR]
#
# DATA_DIR is the measured data (the ColorChecker SG's reflectances, the thesis's measured
# sets, cameras); WORK_DIR (default: a new temporary folder) receives the generated inputs.
set -euo pipefail
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
data="${1:?usage: bash tools/chart_identity.sh DATA_DIR [WORK_DIR]}"
data="$(cd "$data" && pwd)"
work="${2:-$(mktemp -d)}"
mkdir -p "$work"
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$HOME/.cache/spdcam/target}"
cargo build --release -q -p spdcam --bin spdcam
cargo build --release -q -p spdcam-infer --example chart_identity
spdcam="$CARGO_TARGET_DIR/release/spdcam"
measure="$CARGO_TARGET_DIR/release/examples/chart_identity"

# Scene photos: each chart under eight lights, twice (through three cameras in turn, at
# seeds that place the chart differently); the true corners from what render prints.
lights=("--spd A" "--spd D65" "--lighting lamp:phosphor-led --draw 0"
        "--lighting telelumen:config2 --draw 3" "--lighting lamp:fluorescent --draw 1"
        "--lighting lamp:hid --draw 2" "--lighting lamp:mixed-led --draw 5"
        "--lighting gaussian:5 --draw 4")
cameras=(nikon_d5100_npl sigma_sd_merrill_npl canon_eos_5d_mark_ii__camspec)
: > "$work/scenes.tsv"
for chart in colorchecker24 colorchecker_sg140; do
    for i in "${!lights[@]}"; do
        for take in 0 1; do
            camera="${cameras[$(((i + take) % 3))]}"
            photo="$work/scene-$chart-$i-$take.jpg"
            # shellcheck disable=SC2086
            said="$("$spdcam" render --data-dir "$data" --chart "$chart" --camera "$camera" \
                ${lights[$i]} --scene 1200x900 --seed "$((i + 11 + 20 * take))" -o "$photo" 2>&1)"
            corners="$(sed -n 's/.*(chart corners \(.*\))$/\1/p' <<< "$said")"
            printf '%s\t%s\n' "$photo" "$corners" >> "$work/scenes.tsv"
        done
    done
done

# Virtual dataset rows: both charts, every randomisation, a mix of lights.
rows=()
for chart in colorchecker24 colorchecker_sg96; do
    "$spdcam" generate --data-dir "$data" --fast --chart "$chart" --count 400 --seed 5 \
        --lighting "mix:lamp:phosphor-led=0.3,planck=0.2,telelumen:config1=0.3,lamp:fluorescent=0.2" \
        --randomise camera,exposure,wb,tone,jpeg,gradient,floor \
        --cameras "$data/cameras" -o "$work/virtual-$chart" > /dev/null
    "$spdcam" dataset export --csv "$work/virtual-$chart" -o "$work/virtual-$chart-csv" > /dev/null
    rows+=("virtual $chart=$work/virtual-$chart-csv/features.csv")
done
for set in "$data"/thesis/measured/*/; do
    rows+=("measured $(basename "$set")=$set/features.csv")
done
for set in gaussian_4ch_cc24_val telelumen_24ch_cc24_val; do
    rows+=("thesis virtual $set=$data/thesis/virtual/$set/features.csv")
done

cd "$work"
"$measure" "$data" "$work/scenes.tsv" "${rows[@]}"
echo "items: $work/chart-identity-items.tsv" >&2
# As a fresh clone meets them: no data directory, so no SG reflectances (the SG is tested
# by its grey patches' order and the patches' texture alone). Photos only.
mkdir -p "$work/fresh-clone/empty"
cd "$work/fresh-clone"
printf '\nWithout the measured data (photos only):\n\n'
"$measure" "$work/fresh-clone/empty" "$work/scenes.tsv"
echo "items: $work/fresh-clone/chart-identity-items.tsv" >&2
