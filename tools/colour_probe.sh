#!/usr/bin/env bash
# How a model's reading of the light's colour follows the camera's rendering: patch-level
# photos of Planckian and daylight lights (600, seed 7) through the validation split's
# held-out cameras, each with one in-camera rendering (the thesis camera stage that scene
# photos use; a neutral stage with auto exposure; one setting changed from it; the
# randomised stage of the training sets), scored by tools/colour_probe_score.py.
# docs/colour-models.md quotes its output.
#
#   bash tools/colour_probe.sh SPDCAM DATA_DIR SG_MODEL.spdm CC24_MODEL.spdm
set -euo pipefail
spdcam="$(realpath "$1")"; data="$(realpath "$2")"; sg="$(realpath "$3")"; cc24="$(realpath "$4")"
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
mkdir "$work/cameras"
python3 - "$repo/docs/validation-split.json" "$data/cameras" "$work/cameras" <<'PY'
import json, os, sys
split, src, dst = sys.argv[1:]
for name in json.load(open(split))["cameras"]["held_out"]:
    os.symlink(os.path.join(src, name + ".csv"), os.path.join(dst, name + ".csv"))
PY
stage() {  # name, then key=value pairs changed from the neutral stage
    local name="$1"; shift
    python3 - "$work/$name.json" "$@" <<'PY'
import json, sys
stage = {"flare": 0.0, "exposure_target": 0.2, "adaptation": 1.0, "saturation": 1.0, "shoulder": 0.0,
         "gamma": 1.0, "contrast": 0.0, "jpeg_quality": None, "gradient": [0.0, 0.0], "floor": 0.0}
for kv in sys.argv[2:]:
    k, v = kv.split("=")
    stage[k] = float(v)
json.dump(stage, open(sys.argv[1], "w"))
PY
}
stage neutral
stage flare flare=0.15
stage gamma gamma=0.8
stage saturation-0.8 saturation=0.8
stage saturation-1.2 saturation=1.2
probe() {  # chart, model, label, generate options
    local chart="$1" model="$2" label="$3"; shift 3
    "$spdcam" --data-dir "$data" generate --count 600 --seed 7 --fast -o "$work/ds" --force \
        --camera canon_eos_5d_mark_ii --chart "$chart" --cameras "$work/cameras" --camera-variants 0 \
        --lighting "mix:planck=0.5,daylight=0.5" "$@" >/dev/null 2>&1
    "$spdcam" dataset export --csv -o "$work/csv" "$work/ds" --force >/dev/null
    printf '%s, %s: ' "$chart" "$label"
    python3 "$repo/tools/colour_probe_score.py" "$spdcam" "$work/csv" "$model"
}
for pair in "colorchecker_sg96 $sg" "colorchecker24 $cc24"; do
    set -- $pair
    probe "$1" "$2" "thesis camera stage (scene photos)" --randomise camera
    for s in neutral flare gamma saturation-0.8 saturation-1.2; do
        probe "$1" "$2" "$s" --randomise camera --in-camera "$work/$s.json"
    done
    probe "$1" "$2" "randomised stage (training)" --randomise camera,exposure,wb,tone,jpeg,gradient
    probe "$1" "$2" "randomised, full white balance" --randomise camera,exposure,tone,jpeg,gradient
done
