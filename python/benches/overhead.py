"""The Python side's overhead against the Rust library, measured in one process.

For the example photo and for 10,000 feature rows, times the library alone (the compiled
module calls it without any Python conversion) and ``spdcam.estimate`` /
``spdcam.estimate_features`` (the same work plus converting the inputs and results), and
prints the overhead as a share of the Rust time; the goal is at most 5 %. Then a list of
photos in one ``spdcam.estimate`` call (several at once on every core) against the same
photos one call each, as a speed-up.

    python python/benches/overhead.py [--repeats N]
"""

import argparse
import time
from pathlib import Path

import numpy as np

import spdcam
from spdcam import _native

ROOT = Path(__file__).resolve().parents[2]
PHOTO = ROOT / "examples" / "sg-telelumen.jpg"
ROWS = 10_000
#: Photos in the list case.
LIST = 8


def best_of(runs: int, work) -> float:
    """The fastest of `runs` timings of `work()` (seconds); the least disturbed by others."""
    return min(work() for _ in range(runs))


def timed(call):
    def work() -> float:
        start = time.perf_counter()
        call()
        return time.perf_counter() - start

    return work


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5, help="timings per case (best kept)")
    args = parser.parse_args()
    models = spdcam.shipped_model()
    native = models._native

    photo_rust = best_of(args.repeats, lambda: _native.library_seconds_photo(str(PHOTO), native, 1))
    photo_py = best_of(args.repeats, timed(lambda: spdcam.estimate(PHOTO, model=models)))

    features = spdcam.estimate(PHOTO, model=models).detection.features.astype(np.float64)
    rng = np.random.default_rng(1)
    rows = features * rng.uniform(0.5, 1.0, size=(ROWS, 1))
    rows_rust = best_of(args.repeats, lambda: _native.library_seconds_rows(rows.tobytes(), ROWS, native, 1))
    rows_py = best_of(args.repeats, timed(lambda: spdcam.estimate_features(rows, model=models)))

    print(f"{'case':<22}{'Rust (ms)':>11}{'Python (ms)':>13}{'overhead':>10}")
    for name, rust, py in [
        ("photo (example)", photo_rust, photo_py),
        (f"{ROWS:,} feature rows", rows_rust, rows_py),
    ]:
        print(f"{name:<22}{rust * 1e3:>11.1f}{py * 1e3:>13.1f}{(py - rust) / rust:>10.1%}")

    photos = [PHOTO] * LIST
    one_call = best_of(args.repeats, timed(lambda: spdcam.estimate(photos, model=models)))
    each = best_of(args.repeats, timed(lambda: [spdcam.estimate(p, model=models) for p in photos]))
    print(
        f"{LIST} photos: one call {one_call * 1e3:.0f} ms, one call each {each * 1e3:.0f} ms: "
        f"{each / one_call:.2f}× faster as a list"
    )


if __name__ == "__main__":
    main()
