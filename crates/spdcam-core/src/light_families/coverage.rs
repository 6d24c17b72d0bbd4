//! How well a lighting recipe covers measured SPDs: for each measured SPD, the best GFC
//! (400–700 nm) among `n` draws of the recipe. A gap in the prior over lights shows here
//! before any model is trained on it.

use super::Lighting;
use crate::error::{Error, Result};
use crate::spectral::Spd;
use rayon::prelude::*;

/// The wavelengths GFC is taken over, as indices of the lighting's grid.
fn visible(lighting: &Lighting) -> Vec<usize> {
    let g = lighting.grid();
    (0..g.count)
        .filter(|&k| (400.0 - 1e-9..=700.0 + 1e-9).contains(&g.wavelength(k)))
        .collect()
}

/// Unit vector of `spd` on `keep`; `None` for a dark SPD.
fn unit(spd: &[f64], keep: &[usize]) -> Option<Vec<f64>> {
    let v: Vec<f64> = keep.iter().map(|&k| spd[k]).collect();
    let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    (norm > 0.0 && norm.is_finite()).then(|| v.iter().map(|x| x / norm).collect())
}

/// For each of `targets` (SPDs on the lighting's grid), the best GFC over draws `0..n` of
/// `lighting` under `seed`. Dark targets score 0.
pub fn best_gfc(lighting: &Lighting, seed: u64, n: u64, targets: &[Spd]) -> Result<Vec<f64>> {
    if n == 0 {
        return Err(Error::invalid("coverage needs at least one draw"));
    }
    crate::limits::DRAWS.check(n, &format!("coverage of '{}'", lighting.spec()))?;
    let keep = visible(lighting);
    let targets = targets
        .iter()
        .map(|t| Ok(unit(t.on(lighting.grid(), "the lighting")?, &keep)))
        .collect::<Result<Vec<Option<Vec<f64>>>>>()?;
    let draws = (0..n)
        .into_par_iter()
        .map(|i| Ok(unit(&lighting.draw(seed, i)?.spd, &keep)))
        .collect::<Result<Vec<Option<Vec<f64>>>>>()?;
    let draws: Vec<Vec<f64>> = draws.into_iter().flatten().collect();
    Ok(targets
        .par_iter()
        .map(|t| match t {
            None => 0.0,
            Some(t) => draws
                .iter()
                .map(|d| d.iter().zip(t).map(|(a, b)| a * b).sum::<f64>())
                .fold(0.0, f64::max),
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builtin::DataDir;
    use crate::spectral::{Grid, Spd};

    #[test]
    fn a_recipe_covers_its_own_members_and_not_a_line() {
        let grid = Grid::SIMULATION;
        let lighting = Lighting::parse("planck:2000-3000", &DataDir::new(None), &grid).unwrap();
        let member = lighting.draw(9, 3).unwrap().spd;
        let line: Vec<f64> = (0..grid.count)
            .map(|k| {
                if grid.wavelength(k) == 450.0 {
                    1.0
                } else {
                    0.0
                }
            })
            .collect();
        let line = Spd::new(grid, line).unwrap();
        let dark = Spd::new(grid, vec![0.0; grid.count]).unwrap();
        let best = best_gfc(&lighting, 9, 50, &[member, line, dark]).unwrap();
        assert!((best[0] - 1.0).abs() < 1e-12, "{best:?}");
        // A line at 450 nm against a 2,000–3,000 K Planckian: its share of the
        // Planckian's energy at 450 nm, small.
        assert!(best[1] < 0.1, "{best:?}");
        assert_eq!(best[2], 0.0);
        assert!(best_gfc(&lighting, 9, 0, &[]).is_err());
    }
}
