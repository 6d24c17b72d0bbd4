//! Property tests (proptest) of the parsers' round trips: what spdcam writes, it reads back
//! unchanged — spectral CSV, wavelength ranges, shards.

use proptest::prelude::*;
use spdcam_core::dataset::Shard;
use spdcam_core::spectral::{Grid, SpectralSet};

/// Column names as users write them: letters, digits, spaces, commas, quotes, dots, µ, no
/// surrounding spaces (the reader trims cells).
fn name() -> impl Strategy<Value = String> {
    "[A-Za-z0-9µ_]([A-Za-z0-9µ_ ,\".:()-]{0,12}[A-Za-z0-9µ_)])?"
}

/// A spectral set of 2–40 strictly increasing wavelengths and 1–5 uniquely named items of
/// any finite values.
fn spectral_set() -> impl Strategy<Value = SpectralSet> {
    (
        2usize..40,
        prop::collection::btree_set(name(), 1..5),
        // Wavelengths from 200 nm on: a file with none in 200–2500 nm is refused as not in
        // nanometres.
        200.0f64..2000.0,
    )
        .prop_flat_map(|(n, names, start)| {
            let names: Vec<String> = names.into_iter().collect();
            let steps = prop::collection::vec(1e-3f64..50.0, n - 1);
            let values = prop::collection::vec(
                prop::collection::vec(prop::num::f64::NORMAL | prop::num::f64::ZERO, n),
                names.len(),
            );
            (Just(start), steps, Just(names), values)
        })
        .prop_map(|(start, steps, names, values)| {
            let mut wavelengths = vec![start];
            for s in steps {
                let next = wavelengths[wavelengths.len() - 1] + s;
                wavelengths.push(next);
            }
            SpectralSet::new(wavelengths, names, values).expect("a valid set")
        })
}

proptest! {
    #[test]
    fn spectral_csv_reads_back_unchanged(set in spectral_set()) {
        let text = set.to_csv_string();
        let back = SpectralSet::from_csv_str(&text, "round-trip.csv")
            .map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
        prop_assert_eq!(back, set);
    }

    #[test]
    fn wavelength_ranges_read_back_from_their_label(
        start in 0u32..2000,
        step_tenths in 1u32..500,
        count in 1usize..=4001,
    ) {
        let step = f64::from(step_tenths) / 10.0;
        let end = f64::from(start) + step * (count - 1) as f64;
        let grid = Grid::new(f64::from(start), end, step).unwrap();
        prop_assert_eq!(grid.count, count);
        let back = Grid::parse(&grid.label()).unwrap();
        prop_assert_eq!(back.count, grid.count);
        prop_assert_eq!(back.start_nm, grid.start_nm);
        prop_assert_eq!(back.step_nm, grid.step_nm);
    }

    #[test]
    fn shards_read_back_from_their_text(count in 1u32..10_000, pick in 0u32..10_000) {
        let shard = Shard { index: pick % count, count };
        prop_assert_eq!(Shard::parse(&shard.to_string()).unwrap(), shard);
    }

    #[test]
    fn any_text_is_a_spectral_set_or_an_error(text in "\\PC{0,200}") {
        // Never a panic: the fuzz target's property, sampled on every test run.
        let _ = SpectralSet::from_csv_str(&text, "any.csv");
        let _ = Grid::parse(&text);
        let _ = Shard::parse(&text);
    }
}
