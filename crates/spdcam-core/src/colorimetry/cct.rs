//! Correlated colour temperature and Duv by Ohno (2014).
//!
//! Y. Ohno (2014), "Practical use and calculation of CCT and Duv", LEUKOS 10(1), 47–55,
//! doi:10.1080/15502724.2014.839020. The Planckian locus is tabulated in CIE 1960 (u, v) from
//! Planck's law ([`crate::cie_illuminant::PLANCK_C1`], [`crate::cie_illuminant::PLANCK_C2`]) and the
//! CIE 1931 2° CMFs (plain sum over their native 360–830 nm at 1 nm); the table point nearest
//! the test chromaticity and its two neighbours give the CCT by Ohno's triangular solution
//! when |Duv| < 0.002 and by his parabolic solution otherwise. This is the method of
//! colour-science's `uv_to_CCT_Ohno2013`. The table here is geometric with ratio 1.001 per
//! step (4,609 temperatures, the spacing colour-science uses by default), fine enough that
//! Ohno's correction factor for a 1 % table and his cascade of ever finer tables are not
//! needed: on the reference cases the CCT is within 0.04 K of the exact minimum-distance
//! solution and Duv within 1e-8.
//!
//! The nearest table point is found by bisection, not by scanning the table: along the locus
//! the squared distance to the test point falls while the test point lies ahead of the
//! locus's normal at that temperature (Robertson's (1968) isotemperature lines, which do not
//! cross each other this close to the locus), so the sign of the projection of the test point
//! onto the locus's local direction changes once, and ⌈log₂ 4,609⌉ = 13 steps find where.
//! For |Duv| ≤ 0.05 (the range within which CIE 015:2018 defines a CCT) this gives the same
//! table point as a full scan, at every point of a dense test set.

use super::observer::cie1931_native;
use crate::cie_illuminant::planck_radiance;
use crate::error::{Error, Result};
use std::sync::OnceLock;

/// Lowest CCT [`uv_to_cct_duv`] returns, in kelvin.
pub const CCT_MIN_K: f64 = 1000.0;
/// Highest CCT [`uv_to_cct_duv`] returns, in kelvin.
pub const CCT_MAX_K: f64 = 100_000.0;

/// Steps of the Planckian table between [`CCT_MIN_K`] and [`CCT_MAX_K`] (ratio ≈ 1.001).
const TABLE_STEPS: usize = 4608;

/// (u, v) of a Planckian radiator at `t` kelvin; NaN where the radiance underflows.
fn planck_uv(t: f64) -> [f64; 2] {
    let cmf = cie1931_native();
    let mut xyz = [0.0; 3];
    for (i, &w) in cmf.wavelengths().iter().enumerate() {
        let l = planck_radiance(w, t);
        for (c, acc) in xyz.iter_mut().enumerate() {
            *acc += l * cmf.item(c)[i];
        }
    }
    let d = xyz[0] + 15.0 * xyz[1] + 3.0 * xyz[2];
    [4.0 * xyz[0] / d, 6.0 * xyz[1] / d]
}

/// The Planckian table: rows (T, u, v) at T geometric from [`CCT_MIN_K`] to [`CCT_MAX_K`],
/// each computed the first time it is read. A search touches a few dozen of the 4,609 rows
/// (the bisection's steps and their neighbours), so a process that asks for a handful of CCTs
/// does not pay for the whole table (2.2 million Planck evaluations).
struct PlanckTable;

/// The rows' (u, v), filled on first use.
static TABLE_UV: [OnceLock<[f64; 2]>; TABLE_STEPS + 1] =
    [const { OnceLock::new() }; TABLE_STEPS + 1];

impl PlanckTable {
    /// The number of rows.
    const fn len(&self) -> usize {
        TABLE_STEPS + 1
    }

    /// The temperature of row `i`.
    fn temperature(i: usize) -> f64 {
        if i == TABLE_STEPS {
            CCT_MAX_K
        } else {
            let ratio = (CCT_MAX_K / CCT_MIN_K).ln() / TABLE_STEPS as f64;
            CCT_MIN_K * (ratio * i as f64).exp()
        }
    }

    /// Row `i`: (T, u, v).
    fn row(&self, i: usize) -> [f64; 3] {
        let t = Self::temperature(i);
        let [u, v] = *TABLE_UV[i].get_or_init(|| planck_uv(t));
        [t, u, v]
    }
}

/// The index of the `table` row nearest `uv`, by bisection on the sign of the distance's
/// slope along the locus: row `i` lies before the nearest point while `uv` is ahead of the
/// locus's normal there, `(uv − row i) · (row i+1 − row i−1) > 0`.
fn nearest_row(table: &PlanckTable, [u, v]: [f64; 2]) -> usize {
    let ahead = |i: usize| {
        let (p, c, n) = (table.row(i - 1), table.row(i), table.row(i + 1));
        (u - c[1]) * (n[1] - p[1]) + (v - c[2]) * (n[2] - p[2]) > 0.0
    };
    // The first interior row `k` that `uv` is not ahead of: rows 1..k are behind it.
    let (mut lo, mut hi) = (1, table.len() - 1);
    while lo < hi {
        let mid = lo + (hi - lo) / 2;
        if ahead(mid) {
            lo = mid + 1;
        } else {
            hi = mid;
        }
    }
    let k = lo;
    let dist2 = |i: usize| {
        let r = table.row(i);
        (r[1] - u).powi(2) + (r[2] - v).powi(2)
    };
    (k.saturating_sub(1)..(k + 2).min(table.len()))
        .min_by(|&a, &b| dist2(a).total_cmp(&dist2(b)))
        .unwrap_or(0)
}

/// CIE 1960 (u, v) of the Planckian radiator at `cct` kelvin (Planck's law with the CIE 1931
/// 2° observer, as tabulated for Ohno 2014). Errors on a temperature that is not positive or
/// so low that the radiance underflows (below about 20 K).
pub fn cct_to_uv_planck(cct: f64) -> Result<[f64; 2]> {
    if !(cct.is_finite() && cct > 0.0) {
        return Err(Error::invalid(format!(
            "colour temperature {cct} K is not a positive number"
        )));
    }
    let uv = planck_uv(cct);
    if uv.iter().all(|c| c.is_finite()) {
        Ok(uv)
    } else {
        Err(Error::invalid(format!(
            "colour temperature {cct} K is too low to compute a Planckian chromaticity"
        )))
    }
}

/// (u, v) of the Planckian locus at `t` kelvin. Within the table's range, by quadratic
/// (Lagrange) interpolation in ln T through the three nearest rows: rows 0.1 % apart put
/// its error near 1e-10, and a caller converting many colours (the colour map, once per
/// estimate) pays three table reads instead of a Planck sum over 471 wavelengths. Outside
/// it, Planck's law.
fn locus_uv(t: f64) -> Result<[f64; 2]> {
    let table = PlanckTable;
    let step = (CCT_MAX_K / CCT_MIN_K).ln() / TABLE_STEPS as f64;
    let f = (t / CCT_MIN_K).ln() / step;
    if !(1.0..=(TABLE_STEPS - 1) as f64).contains(&f) {
        return cct_to_uv_planck(t);
    }
    let i = (f.round() as usize).clamp(1, table.len() - 2);
    let x = f - i as f64;
    let (p, c, n) = (table.row(i - 1), table.row(i), table.row(i + 1));
    let at = |k: usize| {
        p[k] * x * (x - 1.0) / 2.0 - c[k] * (x + 1.0) * (x - 1.0) + n[k] * (x + 1.0) * x / 2.0
    };
    Ok([at(1), at(2)])
}

/// CIE 1960 (u, v) at `cct` kelvin and distance `duv` from the Planckian locus (the inverse
/// calculation of Ohno 2014): the point `duv` along the locus normal at `cct`, positive above
/// the locus (towards green). The normal comes from the locus at `cct` and `cct + 0.01` K, as
/// in colour-science's `CCT_to_uv_Ohno2013`.
pub fn cct_duv_to_uv(cct: f64, duv: f64) -> Result<[f64; 2]> {
    if !duv.is_finite() {
        return Err(Error::invalid(format!("Duv {duv} is not a number")));
    }
    if !(cct.is_finite() && cct > 0.0) {
        return Err(Error::invalid(format!(
            "colour temperature {cct} K is not a positive number"
        )));
    }
    let [u0, v0] = locus_uv(cct)?;
    let [u1, v1] = locus_uv(cct + 0.01)?;
    let (du, dv) = (u0 - u1, v0 - v1);
    let h = du.hypot(dv);
    if h.is_nan() || h <= 0.0 {
        return Err(Error::invalid(format!(
            "colour temperature {cct} K has no Planckian direction to compute"
        )));
    }
    Ok([u0 - duv * dv / h, v0 + duv * du / h])
}

/// Correlated colour temperature (kelvin) and Duv of CIE 1960 chromaticity `uv` by Ohno
/// (2014): triangular solution for |Duv| < 0.002, parabolic otherwise, over a Planckian table
/// of 1,000–100,000 K. Duv is the signed distance in (u, v) to the locus, positive above it
/// (greenish), negative below (pinkish). Errors on non-finite input and on chromaticities
/// whose nearest locus point is at either end of the table (CCT outside 1,000–100,000 K).
pub fn uv_to_cct_duv(uv: [f64; 2]) -> Result<(f64, f64)> {
    let [u, v] = uv;
    if !(u.is_finite() && v.is_finite()) {
        return Err(Error::invalid(format!(
            "chromaticity ({u}, {v}) is not finite"
        )));
    }
    let table = PlanckTable;
    let dist = |row: &[f64; 3]| (row[1] - u).hypot(row[2] - v);
    let m = nearest_row(&table, [u, v]);
    if m == 0 || m == table.len() - 1 {
        return Err(Error::invalid(format!(
            "chromaticity u = {u}, v = {v} has a CCT outside {CCT_MIN_K}–{CCT_MAX_K} K"
        )));
    }
    let (p, c, n) = (table.row(m - 1), table.row(m), table.row(m + 1));
    let (dp, dc, dn) = (dist(&p), dist(&c), dist(&n));

    // Triangular solution (Ohno 2014): project onto the chord between the neighbours.
    let l = (n[1] - p[1]).hypot(n[2] - p[2]);
    let x = (dp * dp - dn * dn + l * l) / (2.0 * l);
    let t_tri = p[0] + (n[0] - p[0]) * x / l;
    let v_chord = p[2] + (n[2] - p[2]) * x / l;
    let sign = if v - v_chord < 0.0 { -1.0 } else { 1.0 };
    let duv_tri = sign * (dp * dp - x * x).max(0.0).sqrt();
    if duv_tri.abs() < 0.002 {
        return Ok((t_tri, duv_tri));
    }

    // Parabolic solution (Ohno 2014): fit d(T) = aT² + bT + c through the three points.
    let (tp, tc, tn) = (p[0], c[0], n[0]);
    let big_x = (tn - tc) * (tp - tn) * (tc - tp);
    let a = (tp * (dn - dc) + tc * (dp - dn) + tn * (dc - dp)) / big_x;
    let b = -(tp * tp * (dn - dc) + tc * tc * (dp - dn) + tn * tn * (dc - dp)) / big_x;
    let cc =
        -(dp * (tn - tc) * tc * tn + dc * (tp - tn) * tp * tn + dn * (tc - tp) * tp * tc) / big_x;
    let t_par = -b / (2.0 * a);
    Ok((t_par, sign * (a * t_par * t_par + b * t_par + cc)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_spans_the_range_at_ratio_1_001() {
        let t = PlanckTable;
        assert_eq!(t.len(), TABLE_STEPS + 1);
        assert_eq!(t.row(0)[0], CCT_MIN_K);
        assert_eq!(t.row(TABLE_STEPS)[0], CCT_MAX_K);
        let ratio = t.row(1)[0] / t.row(0)[0];
        assert!((ratio - 1.001).abs() < 1e-5, "{ratio}");
    }

    #[test]
    fn round_trip_through_cct_duv_to_uv() {
        for &t in &[1500.0, 2856.0, 4000.0, 6504.0, 10_000.0, 30_000.0, 90_000.0] {
            for &duv in &[-0.02, -0.005, -0.001, 0.0, 0.001, 0.005, 0.02] {
                let uv = cct_duv_to_uv(t, duv).unwrap();
                let (t2, duv2) = uv_to_cct_duv(uv).unwrap();
                assert!((t2 / t - 1.0).abs() < 1e-5, "{t} K {duv}: {t2}");
                assert!((duv2 - duv).abs() < 1e-6, "{t} K {duv}: {duv2}");
            }
        }
    }

    /// The table row nearest `uv` by a full scan, the method the bisection replaces.
    fn nearest_row_by_scan(table: &PlanckTable, [u, v]: [f64; 2]) -> usize {
        let dist = |row: [f64; 3]| (row[1] - u).hypot(row[2] - v);
        (0..table.len())
            .min_by(|&a, &b| dist(table.row(a)).total_cmp(&dist(table.row(b))))
            .unwrap()
    }

    #[test]
    fn a_row_read_lazily_is_planck_at_its_temperature() {
        let t = PlanckTable;
        for i in [0, 1, 2303, TABLE_STEPS - 1, TABLE_STEPS] {
            let [temperature, u, v] = t.row(i);
            assert_eq!([u, v], planck_uv(temperature), "row {i}");
        }
    }

    #[test]
    fn bisection_finds_the_row_a_full_scan_finds() {
        let table = &PlanckTable;
        let mut cases = 0;
        for k in 0..=400 {
            let t = 1005.0 * (99_000.0f64 / 1005.0).powf(k as f64 / 400.0);
            for j in -10..=10 {
                let duv = 0.005 * j as f64;
                let uv = cct_duv_to_uv(t, duv).unwrap();
                assert_eq!(
                    nearest_row(table, uv),
                    nearest_row_by_scan(table, uv),
                    "{t} K, Duv {duv}"
                );
                cases += 1;
            }
        }
        assert_eq!(cases, 401 * 21);
    }

    #[test]
    fn bisection_matches_the_scan_on_the_reference_cases() {
        let reference: serde_json::Value =
            serde_json::from_str(include_str!("../../tests/reference/colorimetry.json")).unwrap();
        let cases = reference["cct_duv"]["cases"].as_array().unwrap();
        assert!(cases.len() >= 10);
        let table = &PlanckTable;
        for case in cases {
            let uv = [
                case["uv"][0].as_f64().unwrap(),
                case["uv"][1].as_f64().unwrap(),
            ];
            let m = nearest_row(table, uv);
            assert_eq!(m, nearest_row_by_scan(table, uv), "{}", case["source"]);
            // colour-science's Ohno 2013 CCT lies between the neighbours of the row found.
            let cct = case["CCT"].as_f64().unwrap();
            assert!(
                table.row(m - 1)[0] <= cct && cct <= table.row(m + 1)[0],
                "{}",
                case["source"]
            );
        }
    }

    #[test]
    fn duv_is_positive_above_the_locus() {
        let [u, v] = cct_to_uv_planck(5000.0).unwrap();
        assert!(uv_to_cct_duv([u, v + 0.01]).unwrap().1 > 0.0);
        assert!(uv_to_cct_duv([u, v - 0.01]).unwrap().1 < 0.0);
        assert!(cct_duv_to_uv(5000.0, 0.01).unwrap()[1] > v);
    }

    #[test]
    fn out_of_range_inputs_are_errors() {
        assert!(uv_to_cct_duv([f64::NAN, 0.3]).is_err());
        // Far red of 1000 K and far blue of 100,000 K.
        let low = cct_to_uv_planck(800.0).unwrap();
        assert!(uv_to_cct_duv(low).is_err());
        let high = cct_to_uv_planck(200_000.0).unwrap();
        assert!(uv_to_cct_duv(high).is_err());
        assert!(cct_to_uv_planck(0.0).is_err());
        assert!(cct_to_uv_planck(-1.0).is_err());
        assert!(cct_to_uv_planck(5.0).is_err());
        assert!(cct_duv_to_uv(5000.0, f64::INFINITY).is_err());
    }

    #[test]
    fn the_interpolated_locus_is_planck_within_1e_10() {
        // Between table rows, on a row, and outside the table (exact there).
        for t in [
            1000.5, 1850.0, 2856.0, 4000.0, 6504.0, 12_345.6, 60_000.0, 99_000.0, 500.0,
        ] {
            let uv = locus_uv(t).unwrap();
            let exact = cct_to_uv_planck(t).unwrap();
            assert!(
                (uv[0] - exact[0]).abs() < 1e-10 && (uv[1] - exact[1]).abs() < 1e-10,
                "{t} K: {uv:?} vs {exact:?}"
            );
        }
    }
}
