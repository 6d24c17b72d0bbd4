"""A 24-megapixel JPEG to a judged SPD, against Pillow decoding the same JPEG (issue 52's
goal: at most twice Pillow's time, both timed as whole commands).

    python python/benches/jpeg_vs_pillow.py [--runs N] [--spdcam PATH]

Renders a ColorChecker 24 scene of 6000 x 4000 pixels under CIE A with the virtual camera
(`spdcam render ... --scene 6000x4000 -o big.jpg`), then runs, in turn and N times each,
`spdcam estimate big.jpg` and a Python process that opens the same file with Pillow and
decodes it (`Image.open(path).load()`). Pairing the runs keeps the ratio meaningful when the
machine's speed drifts; the median of the pairs' ratios is printed beside each command's
median time. Needs Pillow and a release build of spdcam (`cargo build --release`, or
`--spdcam PATH`).
"""
import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def default_spdcam():
    """The release binary of the target directory cargo uses here."""
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    return target / "release" / "spdcam"


def timed(command):
    """Seconds the command takes as a whole process; fails loudly if it fails."""
    start = time.perf_counter()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - start


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7)
    parser.add_argument("--spdcam", type=Path, default=default_spdcam())
    args = parser.parse_args()
    if args.runs < 1:
        parser.error("--runs must be 1 or more")
    if not args.spdcam.is_file():
        sys.exit(f"no spdcam binary at {args.spdcam}: run `cargo build --release` first")
    with tempfile.TemporaryDirectory() as scratch:
        photo = Path(scratch) / "big.jpg"
        subprocess.run(
            [
                str(args.spdcam), "render", "--spd", "A", "--chart", "colorchecker24",
                "--camera", "nikon_d5100_npl", "--scene", "6000x4000", "-o", str(photo),
            ],
            check=True,
            stdout=subprocess.DEVNULL,
        )
        estimate = [str(args.spdcam), "estimate", str(photo)]
        pillow = [
            sys.executable, "-c",
            f"from PIL import Image; Image.open({str(photo)!r}).load()",
        ]
        # One unmeasured run of each: the file and the binaries in the page cache.
        timed(estimate)
        timed(pillow)
        pairs = [(timed(estimate), timed(pillow)) for _ in range(args.runs)]
    ours = statistics.median(p[0] for p in pairs)
    theirs = statistics.median(p[1] for p in pairs)
    ratio = statistics.median(p[0] / p[1] for p in pairs)
    print(
        f"24 MP JPEG ({args.runs} paired runs): spdcam estimate {ours:.3f} s, "
        f"Pillow decode {theirs:.3f} s -> {ratio:.2f}x Pillow (goal <= 2x)"
    )


if __name__ == "__main__":
    main()
