//! Demosaicing: rebuilding three channels from a Bayer mosaic.
//!
//! Every method reads the mosaic with mirror borders (whole-sample symmetric, `c b | a b c …`,
//! scipy's `mode='mirror'`). A mirror keeps the Bayer phase across the edge, so the kernels see
//! a valid neighbourhood everywhere: a flat colour comes back flat up to the last pixel, with no
//! dark or tinted fringe.
//!
//! The work is a short chain of passes over rows. Each pass writes whole planes; the planes that
//! later passes read carry a two-pixel border (mirrored, or zero where the method asks for a
//! zero border), so that the inner loops run over plain slices without index arithmetic and
//! vectorise (in an AVX2 build where the CPU has it). Images above 200 000 pixels split each
//! pass into bands of rows over rayon; smaller ones stay on the calling thread, which is what a
//! caller that already works on many images at once wants. Scratch planes are kept per thread
//! between calls.

use std::cell::RefCell;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::raster::{CfaPattern, Mosaic, RgbImage};

/// Demosaicing methods, named after their papers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DemosaicMethod {
    /// Bilinear interpolation of each channel from its nearest samples of that channel (the
    /// classic 3×3 kernels, the baseline in Losson, Macaire & Yang (2010), "Comparison of color
    /// demosaicing methods"). Cheap, but blurs and leaves colour fringes at edges.
    Bilinear,
    /// Malvar, He & Cutler (2004), "High-quality linear interpolation for demosaicing of
    /// Bayer-patterned color images", ICASSP: bilinear estimates corrected by the Laplacian of
    /// the channel sampled at the pixel (fixed 5×5 kernels). Still linear and fast, much
    /// sharper than bilinear.
    Malvar2004,
    /// Menon, Andriani & Calvagno (2007), "Demosaicing with directional filtering and a
    /// posteriori decision", IEEE Trans. Image Processing 16(1): green is interpolated along
    /// rows and along columns, the direction with the smaller colour-difference gradients in a
    /// 5×5 window wins, red and blue follow from colour differences, and the paper's refining
    /// step then re-filters all three along the chosen direction. The best of the three at edges.
    Menon2007,
}

impl DemosaicMethod {
    /// Every method, from the cheapest to the best.
    pub const ALL: [DemosaicMethod; 3] = [
        DemosaicMethod::Bilinear,
        DemosaicMethod::Malvar2004,
        DemosaicMethod::Menon2007,
    ];

    /// The method's short name: `bilinear`, `malvar2004` or `menon2007`.
    pub fn name(self) -> &'static str {
        match self {
            DemosaicMethod::Bilinear => "bilinear",
            DemosaicMethod::Malvar2004 => "malvar2004",
            DemosaicMethod::Menon2007 => "menon2007",
        }
    }
}

impl std::str::FromStr for DemosaicMethod {
    type Err = crate::Error;

    /// Parses a short name as [`DemosaicMethod::name`] gives it, in any case.
    fn from_str(text: &str) -> crate::Result<DemosaicMethod> {
        DemosaicMethod::ALL
            .into_iter()
            .find(|method| method.name().eq_ignore_ascii_case(text))
            .ok_or_else(|| crate::Error::UnknownName {
                kind: "demosaicing method",
                name: text.to_string(),
                valid: DemosaicMethod::ALL.map(|m| m.name()).join(", "),
            })
    }
}

/// Rebuilds a full RGB image from `mosaic` with `method`.
pub fn demosaic(mosaic: &Mosaic, method: DemosaicMethod) -> RgbImage {
    let mut out = RgbImage {
        width: 0,
        height: 0,
        planes: [Vec::new(), Vec::new(), Vec::new()],
    };
    demosaic_into(mosaic, method, &mut out);
    out
}

/// Rebuilds a full RGB image from `mosaic` with `method` into `out`, reusing its buffers (they
/// are resized to the mosaic's size), so that a loop over many images allocates no output.
///
/// Sizes from 2×2 up work on all four Bayer layouts; odd sizes are fine.
///
/// # Panics
/// If `mosaic.data` does not hold `width × height` values.
pub fn demosaic_into(mosaic: &Mosaic, method: DemosaicMethod, out: &mut RgbImage) {
    let parallel = mosaic.width * mosaic.height > PARALLEL_PIXELS;
    demosaic_with(
        mosaic,
        method,
        out,
        parallel && rayon::current_num_threads() > 1,
    );
}

/// Images with more pixels than this run each pass over bands of rows in parallel.
const PARALLEL_PIXELS: usize = 200_000;

/// Width of the border around intermediate planes: the widest tap of any pass.
const PAD: usize = 2;

/// Padded scratch planes [`menon2007`] needs besides the padded mosaic.
const MENON_PLANES: usize = 6;

thread_local! {
    /// Scratch planes kept between calls on a thread: the padded mosaic first, then the
    /// intermediate planes. Fresh allocations of this size would be page-faulted in anew on
    /// every call, which costs as much as the demosaicing itself. A thread keeps what its
    /// largest image needed (7 planes of (w + 4) × (h + 4) floats for Menon2007).
    static SCRATCH: RefCell<Vec<Vec<f32>>> = const { RefCell::new(Vec::new()) };
}

/// [`demosaic_into`] with the choice of threading made by the caller.
fn demosaic_with(mosaic: &Mosaic, method: DemosaicMethod, out: &mut RgbImage, parallel: bool) {
    let (w, h) = (mosaic.width, mosaic.height);
    assert_eq!(
        mosaic.data.len(),
        w * h,
        "mosaic data holds {} values for {w}×{h} pixels",
        mosaic.data.len()
    );
    out.width = w;
    out.height = h;
    for plane in &mut out.planes {
        plane.resize(w * h, 0.0);
    }
    if w == 0 || h == 0 {
        return;
    }
    let grid = Grid { w, h, parallel };
    let planes = match method {
        DemosaicMethod::Menon2007 => 1 + MENON_PLANES,
        _ => 1,
    };
    // Taken rather than borrowed: a nested call on this thread (rayon may run one while this
    // call waits for its bands) then simply works with fresh planes.
    let mut scratch = SCRATCH.with(|cell| std::mem::take(&mut *cell.borrow_mut()));
    if scratch.len() < planes {
        scratch.resize_with(planes, Vec::new);
    }
    for plane in &mut scratch[..planes] {
        plane.resize(grid.plane_len(), 0.0);
    }
    let (padded, work) = scratch.split_at_mut(1);
    let padded = &mut padded[0];
    grid.pad_mosaic(&mosaic.data, padded);
    let [r, g, b] = &mut out.planes;
    let out = [r.as_mut_slice(), g.as_mut_slice(), b.as_mut_slice()];
    match method {
        DemosaicMethod::Bilinear => bilinear(grid, mosaic.pattern, padded, out),
        DemosaicMethod::Malvar2004 => malvar2004(grid, mosaic.pattern, padded, out),
        DemosaicMethod::Menon2007 => {
            let work = (&mut work[..MENON_PLANES])
                .try_into()
                .expect("scratch planes");
            menon2007(grid, mosaic.pattern, padded, work, out);
        }
    }
    SCRATCH.with(|cell| *cell.borrow_mut() = scratch);
}

/// Whole-sample symmetric index: where position `i` of a signal of length `n` mirrors to.
fn reflect(i: isize, n: usize) -> usize {
    if n == 1 {
        return 0;
    }
    let period = 2 * (n as isize - 1);
    let i = i.rem_euclid(period);
    (if i >= n as isize { period - i } else { i }) as usize
}

/// How a pass fills the border of the planes it writes.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Border {
    /// Unpadded planes: the output image.
    None,
    /// A [`PAD`]-wide mirror border.
    Mirror,
    /// A [`PAD`]-wide border of zeros.
    Zero,
}

/// Size of the image being rebuilt and whether its passes run on several threads.
#[derive(Clone, Copy)]
struct Grid {
    w: usize,
    h: usize,
    parallel: bool,
}

impl Grid {
    /// Width of a padded row.
    fn pw(self) -> usize {
        self.w + 2 * PAD
    }

    /// Length of a padded plane.
    fn plane_len(self) -> usize {
        self.pw() * (self.h + 2 * PAD)
    }

    /// The `N` padded rows centred on interior row `y` of `plane` (rows y − N/2 ..= y + N/2).
    #[inline]
    fn window<const N: usize>(self, plane: &[f32], y: usize) -> [&[f32]; N] {
        let pw = self.pw();
        let first = y + PAD - N / 2;
        std::array::from_fn(|k| &plane[(first + k) * pw..(first + k + 1) * pw])
    }

    /// Copies the row-major `data` into the padded `plane` with a mirror border.
    fn pad_mosaic(self, data: &[f32], plane: &mut [f32]) {
        let w = self.w;
        self.pass(Border::Mirror, [plane], |y, [row]| {
            row.copy_from_slice(&data[y * w..(y + 1) * w]);
        });
    }

    /// Runs `row(y, rows)` for every interior row `y`, where `rows` are the `w` interior values
    /// of row `y` of each plane in `planes`, then fills the planes' border as `border` says.
    /// Bands of rows go to rayon when the grid is parallel.
    fn pass<const N: usize, F>(self, border: Border, mut planes: [&mut [f32]; N], row: F)
    where
        F: Fn(usize, [&mut [f32]; N]) + Sync,
    {
        let pad = if border == Border::None { 0 } else { PAD };
        let (w, h) = (self.w, self.h);
        let pw = w + 2 * pad;
        let edges = edge_columns(w);
        let run_band = |y0: usize, mut band: [&mut [f32]; N]| {
            for r in 0..band[0].len() / pw {
                let mut lines = band.each_mut().map(|p| &mut p[r * pw..(r + 1) * pw]);
                row(y0 + r, lines.each_mut().map(|l| &mut l[pad..pad + w]));
                if border != Border::None {
                    for line in &mut lines {
                        for &(edge, source) in &edges {
                            line[edge] = if border == Border::Mirror {
                                line[source]
                            } else {
                                0.0
                            };
                        }
                    }
                }
            }
        };
        {
            let interior = planes.each_mut().map(|p| &mut p[pad * pw..(pad + h) * pw]);
            if self.parallel {
                let band_rows = h.div_ceil(4 * rayon::current_num_threads()).max(8);
                let mut rest = interior;
                let mut bands = Vec::with_capacity(h.div_ceil(band_rows));
                let mut y0 = 0;
                while y0 < h {
                    let n = band_rows.min(h - y0);
                    let band = rest.each_mut().map(|p| {
                        let (head, tail) = std::mem::take(p).split_at_mut(n * pw);
                        *p = tail;
                        head
                    });
                    bands.push((y0, band));
                    y0 += n;
                }
                bands
                    .into_par_iter()
                    .for_each(|(y0, band)| run_band(y0, band));
            } else {
                run_band(0, interior);
            }
        }
        if border != Border::None {
            for plane in &mut planes {
                fill_rows(plane, w, h, border);
            }
        }
    }
}

/// The border columns of a padded row holding `w` interior values, each with the column it
/// mirrors: `(border, source)` positions in the padded row.
fn edge_columns(w: usize) -> [(usize, usize); 2 * PAD] {
    std::array::from_fn(|i| {
        let k = i / 2 + 1;
        if i.is_multiple_of(2) {
            (PAD - k, PAD + reflect(-(k as isize), w))
        } else {
            (PAD + w - 1 + k, PAD + reflect((w - 1 + k) as isize, w))
        }
    })
}

/// Fills the [`PAD`] rows above and below the `h` interior rows of a padded plane.
fn fill_rows(plane: &mut [f32], w: usize, h: usize, border: Border) {
    let pw = w + 2 * PAD;
    for k in 1..=PAD {
        for (dst, src) in [
            (PAD - k, reflect(-(k as isize), h)),
            (PAD + h - 1 + k, reflect((h - 1 + k) as isize, h)),
        ] {
            if border == Border::Mirror {
                plane.copy_within((PAD + src) * pw..(PAD + src + 1) * pw, dst * pw);
            } else {
                plane[dst * pw..(dst + 1) * pw].fill(0.0);
            }
        }
    }
}

/// Which samples row `y` holds: the x parity of its greens, and the channel of the others.
#[derive(Clone, Copy)]
struct RowLayout {
    /// x parity (0 or 1) of the row's green samples.
    green: usize,
    /// Channel of the row's other samples: 0 (R) or 2 (B).
    own: usize,
}

impl RowLayout {
    fn of(pattern: CfaPattern, y: usize) -> RowLayout {
        let first = pattern.channel_at(0, y);
        if first == 1 {
            RowLayout {
                green: 0,
                own: pattern.channel_at(1, y),
            }
        } else {
            RowLayout {
                green: 1,
                own: first,
            }
        }
    }

    /// `(own, other)`: of the red and blue planes, the row's own colour and the other one.
    fn split<T>(self, red: T, blue: T) -> (T, T) {
        if self.own == 0 {
            (red, blue)
        } else {
            (blue, red)
        }
    }

    /// +1 in a red row, −1 in a blue one: the sign of R − B as own − other.
    fn sign(self) -> f32 {
        if self.own == 0 {
            1.0
        } else {
            -1.0
        }
    }
}

/// `w` values of a padded row, shifted by `dx` ∈ −2..=2 from the interior.
#[inline]
fn tap(row: &[f32], dx: isize, w: usize) -> &[f32] {
    let start = PAD.wrapping_add_signed(dx);
    &row[start..start + w]
}

// The row kernels below take each output as its own `&mut` argument, so the compiler knows that
// outputs and inputs never overlap, and choose between values with `pick` on bit masks rather
// than with `if`: both are needed for their loops to vectorise on baseline x86-64 (SSE2). The
// passes call them through `wide`, which adds an AVX2 build.

/// Defines, for a row kernel of the parent module, a function of the same name and arguments
/// that runs the kernel compiled for AVX2 where the CPU has it: eight pixels per instruction
/// instead of four, about 1.5× faster. Both builds do the same IEEE operations on every pixel,
/// so their results are identical.
macro_rules! wide_kernel {
    ($name:ident($($arg:ident: $ty:ty),* $(,)?)) => {
        pub(super) fn $name($($arg: $ty),*) {
            #[cfg(target_arch = "x86_64")]
            if std::arch::is_x86_feature_detected!("avx2") {
                #[target_feature(enable = "avx2")]
                fn avx2($($arg: $ty),*) {
                    super::$name($($arg),*)
                }
                // SAFETY: the CPU supports AVX2, as checked just above.
                return unsafe { avx2($($arg),*) };
            }
            super::$name($($arg),*)
        }
    };
}

/// The row kernels, each run in the widest vector build the CPU supports.
mod wide {
    use super::RowLayout;

    type Rows<'a, const N: usize> = [&'a [f32]; N];

    wide_kernel!(bilinear_row(
        own: &mut [f32], g: &mut [f32], other: &mut [f32], m: Rows<3>, gpar: usize
    ));
    wide_kernel!(malvar_row(
        own: &mut [f32], g: &mut [f32], other: &mut [f32], m: Rows<5>, gpar: usize
    ));
    wide_kernel!(menon_differences_row(
        ch: &mut [f32], cv: &mut [f32], m: Rows<5>, gpar: usize
    ));
    wide_kernel!(menon_gradients_row(
        dh: &mut [f32], dv: &mut [f32], ch: &[f32], cv: Rows<5>
    ));
    wide_kernel!(menon_decision_row(
        g: &mut [f32], hz: &mut [f32], grads: [Rows<5>; 2], here: Rows<3>
    ));
    wide_kernel!(menon_green_sites_row(
        own: &mut [f32], other: &mut [f32], rows: [Rows<3>; 2], gpar: usize
    ));
    wide_kernel!(menon_cross_row(
        cross: &mut [f32], refined: &mut [f32], rows: [Rows<3>; 3], hz: &[f32], gpar: usize
    ));
    wide_kernel!(menon_red_blue_row(
        rb: &mut [f32], rows: [Rows<3>; 2], cross: &[f32], layout: RowLayout
    ));
    wide_kernel!(menon_output_row(
        own: &mut [f32], g: &mut [f32], other: &mut [f32],
        rows: [Rows<3>; 3], hz: &[f32], layout: RowLayout
    ));
}

/// All ones where pixel `x` of a row is green (its greens have x parity `gpar`), else zero.
#[inline(always)]
fn green_mask(x: usize, gpar: usize) -> u32 {
    0u32.wrapping_sub((x as u32 ^ gpar as u32 ^ 1) & 1)
}

/// All ones if `b`, else zero.
#[inline(always)]
fn mask(b: bool) -> u32 {
    0u32.wrapping_sub(u32::from(b))
}

/// `a` where `mask` is all ones, `b` where it is zero.
#[inline(always)]
fn pick(mask: u32, a: f32, b: f32) -> f32 {
    f32::from_bits((a.to_bits() & mask) | (b.to_bits() & !mask))
}

/// [`DemosaicMethod::Bilinear`]: each missing value is the mean of the nearest two or four
/// samples of its channel.
fn bilinear(grid: Grid, pattern: CfaPattern, mosaic: &[f32], out: [&mut [f32]; 3]) {
    grid.pass(Border::None, out, |y, [r, g, b]| {
        let layout = RowLayout::of(pattern, y);
        let (own, other) = layout.split(r, b);
        wide::bilinear_row(own, g, other, grid.window(mosaic, y), layout.green);
    });
}

#[inline(always)]
fn bilinear_row(own: &mut [f32], g: &mut [f32], other: &mut [f32], m: [&[f32]; 3], gpar: usize) {
    let w = own.len();
    let (g, other) = (&mut g[..w], &mut other[..w]);
    let [up, mid, down] = m;
    let (ul, u, ur) = (tap(up, -1, w), tap(up, 0, w), tap(up, 1, w));
    let (l, c, r) = (tap(mid, -1, w), tap(mid, 0, w), tap(mid, 1, w));
    let (dl, d, dr) = (tap(down, -1, w), tap(down, 0, w), tap(down, 1, w));
    for x in 0..w {
        let green = green_mask(x, gpar);
        let horizontal = 0.5 * (l[x] + r[x]);
        let vertical = 0.5 * (u[x] + d[x]);
        let cross = 0.5 * (horizontal + vertical);
        let diagonal = 0.25 * ((ul[x] + ur[x]) + (dl[x] + dr[x]));
        own[x] = pick(green, horizontal, c[x]);
        g[x] = pick(green, c[x], cross);
        other[x] = pick(green, vertical, diagonal);
    }
}

/// [`DemosaicMethod::Malvar2004`]: bilinear estimates plus a Laplacian correction from the
/// channel sampled at the pixel, as the paper's four 5×5 kernels.
fn malvar2004(grid: Grid, pattern: CfaPattern, mosaic: &[f32], out: [&mut [f32]; 3]) {
    grid.pass(Border::None, out, |y, [r, g, b]| {
        let layout = RowLayout::of(pattern, y);
        let (own, other) = layout.split(r, b);
        wide::malvar_row(own, g, other, grid.window(mosaic, y), layout.green);
    });
}

#[inline(always)]
fn malvar_row(own: &mut [f32], g: &mut [f32], other: &mut [f32], m: [&[f32]; 5], gpar: usize) {
    let w = own.len();
    let (g, other) = (&mut g[..w], &mut other[..w]);
    let [up2, up, mid, down, down2] = m;
    let (u2, d2) = (tap(up2, 0, w), tap(down2, 0, w));
    let (ul, u, ur) = (tap(up, -1, w), tap(up, 0, w), tap(up, 1, w));
    let (dl, d, dr) = (tap(down, -1, w), tap(down, 0, w), tap(down, 1, w));
    let (l2, l, c) = (tap(mid, -2, w), tap(mid, -1, w), tap(mid, 0, w));
    let (r, r2) = (tap(mid, 1, w), tap(mid, 2, w));
    for x in 0..w {
        let green = green_mask(x, gpar);
        let near_h = l[x] + r[x];
        let near_v = u[x] + d[x];
        let far_h = l2[x] + r2[x];
        let far_v = u2[x] + d2[x];
        let diagonal = (ul[x] + ur[x]) + (dl[x] + dr[x]);
        let c = c[x];
        // At a green sample: the colour of the row's neighbours and that of the column's.
        let along_row = 0.125 * (5.0 * c + 4.0 * near_h - far_h - diagonal + 0.5 * far_v);
        let along_column = 0.125 * (5.0 * c + 4.0 * near_v - far_v - diagonal + 0.5 * far_h);
        // At a red or blue sample: green, and the opposite colour on the diagonals.
        let far = far_h + far_v;
        let green_here = 0.125 * (4.0 * c + 2.0 * (near_h + near_v) - far);
        let opposite = 0.125 * (6.0 * c + 2.0 * diagonal - 1.5 * far);
        own[x] = pick(green, along_row, c);
        g[x] = pick(green, c, green_here);
        other[x] = pick(green, along_column, opposite);
    }
}

/// [`DemosaicMethod::Menon2007`], with its refining step; stage by stage the same computation
/// as colour-demosaicing's `demosaicing_CFA_Bayer_Menon2007(CFA, pattern, refining_step=True)`.
fn menon2007(
    grid: Grid,
    pattern: CfaPattern,
    mosaic: &[f32],
    work: &mut [Vec<f32>; MENON_PLANES],
    out: [&mut [f32]; 3],
) {
    // Padded planes, renamed as later stages reuse those that earlier ones retire.
    let [diff_h, diff_v, grad_h, grad_v, green, horizontal] = work;

    // 1. Colour differences (R or B) − G at the red and blue samples, with green interpolated
    //    along the row and along the column by [0, ½, 0, ½, 0] + [−¼, 0, ½, 0, −¼]; zero at green.
    grid.pass(Border::Mirror, [diff_h, diff_v], |y, [ch, cv]| {
        let layout = RowLayout::of(pattern, y);
        wide::menon_differences_row(ch, cv, grid.window(mosaic, y), layout.green);
    });

    // 2. Gradients of those differences two pixels along their direction; zero border, as
    //    the reference classifies with a zero-padded ('constant') convolution.
    grid.pass(Border::Zero, [grad_h, grad_v], |y, [dh, dv]| {
        let [ch] = grid.window(diff_h, y);
        wide::menon_gradients_row(dh, dv, ch, grid.window(diff_v, y));
    });

    // 3. The a posteriori decision: sum the gradients over a 5×5 window (the paper's
    //    classifier) and keep the direction with the smaller sum; green follows that direction.
    grid.pass(Border::Mirror, [green, horizontal], |y, [g, hz]| {
        let ([m], [ch], [cv]) = (
            grid.window(mosaic, y),
            grid.window(diff_h, y),
            grid.window(diff_v, y),
        );
        let gradients = [grid.window(grad_h, y), grid.window(grad_v, y)];
        wide::menon_decision_row(g, hz, gradients, [m, ch, cv]);
    });

    // 4. Red and blue at the green samples: green plus the mean colour difference of the two
    //    neighbours that carry the colour (along the row for the row's colour, else the column).
    let (red, blue) = (grad_h, grad_v);
    grid.pass(Border::Mirror, [red, blue], |y, [r, b]| {
        let layout = RowLayout::of(pattern, y);
        let (own, other) = layout.split(r, b);
        let windows = [grid.window(mosaic, y), grid.window(green, y)];
        wide::menon_green_sites_row(own, other, windows, layout.green);
    });

    // 5. Blue at red samples and red at blue ones from the R − B difference of the neighbours
    //    in the chosen direction; and the refining step's green: the sample minus its colour
    //    difference to green averaged over three pixels in that direction.
    let (cross, refined) = (diff_h, diff_v);
    grid.pass(Border::Mirror, [cross, refined], |y, [cr, gf]| {
        let layout = RowLayout::of(pattern, y);
        let (own, other) = layout.split(&*red, &*blue);
        let windows = [
            grid.window(own, y),
            grid.window(other, y),
            grid.window(green, y),
        ];
        let [hz] = grid.window(horizontal, y);
        wide::menon_cross_row(cr, gf, windows, hz, layout.green);
    });

    // 6. Refining step, red and blue at green samples: refined green plus the mean difference
    //    sample − green of the two neighbours carrying the colour. Kept as R − B everywhere.
    let red_blue = red;
    grid.pass(Border::Mirror, [red_blue], |y, [rb]| {
        let layout = RowLayout::of(pattern, y);
        let [cr] = grid.window(cross, y);
        let windows = [grid.window(mosaic, y), grid.window(refined, y)];
        wide::menon_red_blue_row(rb, windows, cr, layout);
    });

    // 7. Refining step, red at blue samples and blue at red ones: the R − B difference averaged
    //    over three pixels in the chosen direction. Writes the image.
    grid.pass(Border::None, out, |y, [r, g, b]| {
        let layout = RowLayout::of(pattern, y);
        let (own, other) = layout.split(r, b);
        let windows = [
            grid.window(mosaic, y),
            grid.window(refined, y),
            grid.window(red_blue, y),
        ];
        let [hz] = grid.window(horizontal, y);
        wide::menon_output_row(own, g, other, windows, hz, layout);
    });
}

/// One third, the weight of Menon's three-tap mean.
const THIRD: f32 = 1.0 / 3.0;

#[inline(always)]
fn menon_differences_row(ch: &mut [f32], cv: &mut [f32], m: [&[f32]; 5], gpar: usize) {
    let w = ch.len();
    let cv = &mut cv[..w];
    let [up2, up, mid, down, down2] = m;
    let (u2, u, d, d2) = (
        tap(up2, 0, w),
        tap(up, 0, w),
        tap(down, 0, w),
        tap(down2, 0, w),
    );
    let (l2, l, c) = (tap(mid, -2, w), tap(mid, -1, w), tap(mid, 0, w));
    let (r, r2) = (tap(mid, 1, w), tap(mid, 2, w));
    for x in 0..w {
        let green = green_mask(x, gpar);
        let h = 0.5 * (c[x] - (l[x] + r[x])) + 0.25 * (l2[x] + r2[x]);
        let v = 0.5 * (c[x] - (u[x] + d[x])) + 0.25 * (u2[x] + d2[x]);
        ch[x] = pick(green, 0.0, h);
        cv[x] = pick(green, 0.0, v);
    }
}

#[inline(always)]
fn menon_gradients_row(dh: &mut [f32], dv: &mut [f32], ch: &[f32], cv: [&[f32]; 5]) {
    let w = dh.len();
    let dv = &mut dv[..w];
    let (h, h2) = (tap(ch, 0, w), tap(ch, 2, w));
    let (v, v2) = (tap(cv[2], 0, w), tap(cv[4], 0, w));
    for x in 0..w {
        dh[x] = (h[x] - h2[x]).abs();
        dv[x] = (v[x] - v2[x]).abs();
    }
}

#[inline(always)]
fn menon_decision_row(
    g: &mut [f32],
    hz: &mut [f32],
    [dh, dv]: [[&[f32]; 5]; 2],
    [m, ch, cv]: [&[f32]; 3],
) {
    let w = g.len();
    let hz = &mut hz[..w];
    let (m, ch, cv) = (tap(m, 0, w), tap(ch, 0, w), tap(cv, 0, w));
    // The horizontal classifier reads x − 2, x − 1 and x; the vertical one is its transpose.
    let [h_u2, h_u, h_c, h_d, h_d2] = dh;
    let (h_u2l, h_u2c) = (tap(h_u2, -2, w), tap(h_u2, 0, w));
    let (h_cl, h_cc) = (tap(h_c, -2, w), tap(h_c, 0, w));
    let (h_d2l, h_d2c) = (tap(h_d2, -2, w), tap(h_d2, 0, w));
    let (h_ul, h_dl) = (tap(h_u, -1, w), tap(h_d, -1, w));
    let [v_u2, v_u, v_c, _, _] = dv;
    let (v_cl, v_cc, v_cr) = (tap(v_c, -2, w), tap(v_c, 0, w), tap(v_c, 2, w));
    let (v_u2l, v_u2c, v_u2r) = (tap(v_u2, -2, w), tap(v_u2, 0, w), tap(v_u2, 2, w));
    let (v_ul, v_ur) = (tap(v_u, -1, w), tap(v_u, 1, w));
    for x in 0..w {
        let sum_h = (h_u2c[x] + h_u2l[x])
            + 3.0 * (h_cc[x] + h_cl[x])
            + (h_d2c[x] + h_d2l[x])
            + (h_ul[x] + h_dl[x]);
        let sum_v = (v_cl[x] + v_cr[x])
            + 3.0 * (v_cc[x] + v_u2c[x])
            + (v_u2l[x] + v_u2r[x])
            + (v_ul[x] + v_ur[x]);
        let along_row = mask(sum_v >= sum_h);
        // The differences are zero at green samples, which so keep their value.
        g[x] = m[x] - pick(along_row, ch[x], cv[x]);
        hz[x] = pick(along_row, 1.0, 0.0);
    }
}

#[inline(always)]
fn menon_green_sites_row(
    own: &mut [f32],
    other: &mut [f32],
    [m, g]: [[&[f32]; 3]; 2],
    gpar: usize,
) {
    let w = own.len();
    let other = &mut other[..w];
    let (ml, mc, mr) = (tap(m[1], -1, w), tap(m[1], 0, w), tap(m[1], 1, w));
    let (gl, gc, gr) = (tap(g[1], -1, w), tap(g[1], 0, w), tap(g[1], 1, w));
    let (mu, md) = (tap(m[0], 0, w), tap(m[2], 0, w));
    let (gu, gd) = (tap(g[0], 0, w), tap(g[2], 0, w));
    for x in 0..w {
        let green = green_mask(x, gpar);
        let along_row = gc[x] + 0.5 * ((ml[x] + mr[x]) - (gl[x] + gr[x]));
        let along_column = gc[x] + 0.5 * ((mu[x] + md[x]) - (gu[x] + gd[x]));
        own[x] = pick(green, along_row, mc[x]);
        other[x] = pick(green, along_column, 0.0);
    }
}

/// `own` and `other` hold the row's colour and the other one after stage 4: the sample itself
/// at its own sites, so `own` is the mosaic there and `green` is the mosaic at green sites.
#[inline(always)]
fn menon_cross_row(
    cross: &mut [f32],
    refined: &mut [f32],
    [own, other, green]: [[&[f32]; 3]; 3],
    hz: &[f32],
    gpar: usize,
) {
    let w = cross.len();
    let refined = &mut refined[..w];
    let hz = tap(hz, 0, w);
    let (ol, oc, or) = (tap(own[1], -1, w), tap(own[1], 0, w), tap(own[1], 1, w));
    let (ou, od) = (tap(own[0], 0, w), tap(own[2], 0, w));
    let (tl, tr) = (tap(other[1], -1, w), tap(other[1], 1, w));
    let (tu, td) = (tap(other[0], 0, w), tap(other[2], 0, w));
    let (gl, gc, gr) = (
        tap(green[1], -1, w),
        tap(green[1], 0, w),
        tap(green[1], 1, w),
    );
    let (gu, gd) = (tap(green[0], 0, w), tap(green[2], 0, w));
    for x in 0..w {
        let is_green = green_mask(x, gpar);
        let along_row = mask(hz[x] != 0.0);
        let c = oc[x];
        let cross_h = 0.5 * ((tl[x] + tr[x]) - (ol[x] + or[x]));
        let cross_v = 0.5 * ((tu[x] + td[x]) - (ou[x] + od[x]));
        let refine_h = ((ol[x] - gl[x]) + (c - gc[x]) + (or[x] - gr[x])) * THIRD;
        let refine_v = ((ou[x] - gu[x]) + (c - gc[x]) + (od[x] - gd[x])) * THIRD;
        let opposite = c + pick(along_row, cross_h, cross_v);
        let green_here = c - pick(along_row, refine_h, refine_v);
        cross[x] = pick(is_green, 0.0, opposite);
        refined[x] = pick(is_green, gc[x], green_here);
    }
}

#[inline(always)]
fn menon_red_blue_row(rb: &mut [f32], [m, f]: [[&[f32]; 3]; 2], cross: &[f32], layout: RowLayout) {
    let w = rb.len();
    let sign = layout.sign();
    let (ml, mc, mr) = (tap(m[1], -1, w), tap(m[1], 0, w), tap(m[1], 1, w));
    let (fl, fr) = (tap(f[1], -1, w), tap(f[1], 1, w));
    let (mu, md, fu, fd) = (
        tap(m[0], 0, w),
        tap(m[2], 0, w),
        tap(f[0], 0, w),
        tap(f[2], 0, w),
    );
    let cross = tap(cross, 0, w);
    for x in 0..w {
        let green = green_mask(x, layout.green);
        // own − other at a green sample, where green cancels.
        let row = (ml[x] - fl[x]) + (mr[x] - fr[x]);
        let column = (mu[x] - fu[x]) + (md[x] - fd[x]);
        let at_green = 0.5 * (row - column);
        let at_colour = mc[x] - cross[x];
        rb[x] = sign * pick(green, at_green, at_colour);
    }
}

#[inline(always)]
fn menon_output_row(
    own: &mut [f32],
    g: &mut [f32],
    other: &mut [f32],
    [m, f, d]: [[&[f32]; 3]; 3],
    hz: &[f32],
    layout: RowLayout,
) {
    let w = own.len();
    let (g, other) = (&mut g[..w], &mut other[..w]);
    let sign = layout.sign();
    let hz = tap(hz, 0, w);
    let (ml, mc, mr) = (tap(m[1], -1, w), tap(m[1], 0, w), tap(m[1], 1, w));
    let (fl, fc, fr) = (tap(f[1], -1, w), tap(f[1], 0, w), tap(f[1], 1, w));
    let (dl, dc, dr) = (tap(d[1], -1, w), tap(d[1], 0, w), tap(d[1], 1, w));
    let (mu, md, fu, fd) = (
        tap(m[0], 0, w),
        tap(m[2], 0, w),
        tap(f[0], 0, w),
        tap(f[2], 0, w),
    );
    let (du, dd) = (tap(d[0], 0, w), tap(d[2], 0, w));
    for x in 0..w {
        let green = green_mask(x, layout.green);
        let own_at_green = fc[x] + 0.5 * ((ml[x] - fl[x]) + (mr[x] - fr[x]));
        let other_at_green = fc[x] + 0.5 * ((mu[x] - fu[x]) + (md[x] - fd[x]));
        let diff_h = (dl[x] + dc[x] + dr[x]) * THIRD;
        let diff_v = (du[x] + dc[x] + dd[x]) * THIRD;
        let other_at_colour = mc[x] - sign * pick(mask(hz[x] != 0.0), diff_h, diff_v);
        own[x] = pick(green, own_at_green, mc[x]);
        g[x] = fc[x];
        other[x] = pick(green, other_at_green, other_at_colour);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An image from a function of (x, y) giving (R, G, B).
    fn image(w: usize, h: usize, f: impl Fn(usize, usize) -> [f32; 3]) -> RgbImage {
        let mut img = RgbImage::new(w, h);
        for y in 0..h {
            for x in 0..w {
                for (plane, value) in img.planes.iter_mut().zip(f(x, y)) {
                    plane[y * w + x] = value;
                }
            }
        }
        img
    }

    /// A deterministic value in [0, 1) from a counter (an LCG step).
    fn hash(i: u64) -> f32 {
        let v = i
            .wrapping_add(1)
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((v >> 40) as f32) / (1u64 << 24) as f32
    }

    /// The 24 ColorChecker colours, sRGB-encoded, 8 bits.
    const COLORCHECKER: [[u8; 3]; 24] = [
        [115, 82, 68],
        [194, 150, 130],
        [98, 122, 157],
        [87, 108, 67],
        [133, 128, 177],
        [103, 189, 170],
        [214, 126, 44],
        [80, 91, 166],
        [193, 90, 99],
        [94, 60, 108],
        [157, 188, 64],
        [224, 163, 46],
        [56, 61, 150],
        [70, 148, 73],
        [175, 54, 60],
        [231, 199, 31],
        [187, 86, 149],
        [8, 133, 161],
        [243, 243, 242],
        [200, 200, 200],
        [160, 160, 160],
        [122, 122, 121],
        [85, 85, 85],
        [52, 52, 52],
    ];

    /// ColorChecker colour `k` (mod 24) in 0..1.
    fn checker(k: usize) -> [f32; 3] {
        COLORCHECKER[k % 24].map(|v| f32::from(v) / 255.0)
    }

    /// 256×256: a tinted zone plate, crossed sinusoidal gratings, bars and discs in ColorChecker
    /// colours with sharp edges.
    fn edge_rich() -> RgbImage {
        use std::f32::consts::TAU;
        image(256, 256, |x, y| {
            let (xf, yf) = (x as f32, y as f32);
            match (x < 128, y < 128) {
                (true, true) => {
                    // Reaches 0.25 cycles/pixel in the corners.
                    let s = (0.0087 * ((xf - 64.0).powi(2) + (yf - 64.0).powi(2))).cos();
                    [0.5 + 0.4 * s, 0.45 + 0.35 * s, 0.4 + 0.3 * s]
                }
                (false, true) => {
                    let a = (TAU * (0.11 * xf + 0.05 * yf)).cos();
                    let b = (TAU * (-0.07 * xf + 0.13 * yf)).cos();
                    let lum = 0.5 + 0.2 * a + 0.2 * b;
                    [1.1 * lum + 0.03 * a, lum, 0.85 * lum + 0.03 * b]
                }
                (true, false) => checker(x / 9 + 3 * (y / 21)),
                (false, false) => {
                    let d2 = ((x % 32) as f32 - 15.5).powi(2) + ((y % 32) as f32 - 15.5).powi(2);
                    if d2 < 120.0 {
                        checker(5 * (x / 32) + 3 * (y / 32))
                    } else {
                        [0.45 + 0.1 * (0.05 * xf).sin(); 3]
                    }
                }
            }
        })
    }

    /// A ColorChecker rendering, 288 × 192: 8 × 12 cells of 24 × 24 pixels, each a patch of one
    /// of the 24 colours (at four exposures, with a gentle shading across the patch) inside the
    /// chart's 4-pixel dark frame.
    fn chart() -> RgbImage {
        image(288, 192, |x, y| {
            let (u, v) = (x % 24, y % 24);
            if u < 4 || v < 4 {
                return [0.04; 3];
            }
            let patch = y / 24 * 12 + x / 24;
            let exposure = [1.0, 0.85, 0.7, 0.55][patch / 24];
            let shade = 1.0 + 0.08 * (u as f32 / 23.0 - 0.5) + 0.05 * (v as f32 / 23.0 - 0.5);
            checker(7 * patch).map(|c| (c * exposure * shade).min(1.0))
        })
    }

    /// PSNR (peak 1) of `got` against `want` over the pixels at least 4 from the border.
    fn psnr(got: &RgbImage, want: &RgbImage) -> f64 {
        let (w, h) = (want.width, want.height);
        let (mut sum, mut n) = (0.0f64, 0usize);
        for y in 4..h - 4 {
            for x in 4..w - 4 {
                for c in 0..3 {
                    let e = f64::from(got.planes[c][y * w + x] - want.planes[c][y * w + x]);
                    sum += e * e;
                    n += 1;
                }
            }
        }
        10.0 * (n as f64 / sum).log10()
    }

    fn assert_close(got: &RgbImage, want: &RgbImage, tol: f32, what: &str) {
        for c in 0..3 {
            for (i, (g, w)) in got.planes[c].iter().zip(&want.planes[c]).enumerate() {
                assert!(
                    (g - w).abs() <= tol,
                    "{what}: channel {c} pixel ({}, {}): {g} vs {w}",
                    i % want.width,
                    i / want.width
                );
            }
        }
    }

    #[test]
    fn names_round_trip() {
        for method in DemosaicMethod::ALL {
            assert_eq!(method.name().parse::<DemosaicMethod>().unwrap(), method);
            let upper = method.name().to_ascii_uppercase();
            assert_eq!(upper.parse::<DemosaicMethod>().unwrap(), method);
        }
        let e = "menon".parse::<DemosaicMethod>().unwrap_err().to_string();
        assert!(e.contains("'menon'") && e.contains("menon2007"), "{e}");
    }

    #[test]
    fn flat_colour_comes_back_everywhere() {
        let sizes = [
            (2, 2),
            (3, 2),
            (2, 3),
            (3, 3),
            (4, 5),
            (5, 5),
            (7, 4),
            (31, 17),
        ];
        for (w, h) in sizes.into_iter().chain([(520, 400)]) {
            let flat = image(w, h, |_, _| [0.2, 0.55, 0.85]);
            for pattern in CfaPattern::ALL {
                let mosaic = Mosaic::from_rgb(&flat, pattern);
                for method in DemosaicMethod::ALL {
                    let got = demosaic(&mosaic, method);
                    assert_eq!((got.width, got.height), (w, h));
                    assert_close(
                        &got,
                        &flat,
                        1e-5,
                        &format!("{method:?} {pattern:?} {w}×{h}"),
                    );
                }
            }
        }
    }

    #[test]
    fn samples_are_kept_at_their_own_channel() {
        let img = image(37, 22, |x, y| {
            [0, 1, 2].map(|c| hash((y * 37 + x) as u64 * 3 + c))
        });
        for pattern in CfaPattern::ALL {
            let mosaic = Mosaic::from_rgb(&img, pattern);
            for method in DemosaicMethod::ALL {
                let got = demosaic(&mosaic, method);
                for y in 0..22 {
                    for x in 0..37 {
                        let c = pattern.channel_at(x, y);
                        assert_eq!(
                            got.pixel(x, y)[c],
                            mosaic.get(x, y),
                            "{method:?} {pattern:?}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn linear_kernels_reproduce_a_ramp() {
        for channel in 0..3 {
            let ramp = image(40, 30, |x, _| {
                let mut rgb = [0.3, 0.5, 0.7];
                rgb[channel] = 0.1 + 0.02 * x as f32;
                rgb
            });
            for pattern in CfaPattern::ALL {
                let mosaic = Mosaic::from_rgb(&ramp, pattern);
                for method in [DemosaicMethod::Bilinear, DemosaicMethod::Malvar2004] {
                    let got = demosaic(&mosaic, method);
                    for y in 2..28 {
                        for x in 2..38 {
                            let (g, w) = (got.pixel(x, y), ramp.pixel(x, y));
                            for c in 0..3 {
                                assert!(
                                    (g[c] - w[c]).abs() < 1e-5,
                                    "{method:?} {pattern:?} ({x}, {y}) {c}: {g:?} vs {w:?}"
                                );
                            }
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn menon_matches_the_reference_example() {
        // demosaicing_CFA_Bayer_Menon2007's documented example (colour-demosaicing), whose
        // values are printed from doubles.
        let data: [f64; 8] = [
            0.309_803_93,
            0.360_784_32,
            0.305_882_36,
            0.376_470_6,
            0.356_862_75,
            0.396_078_44,
            0.360_784_32,
            0.400_000_01,
        ];
        let mosaic = Mosaic {
            width: 4,
            height: 2,
            pattern: CfaPattern::Rggb,
            data: data.map(|v| v as f32).to_vec(),
        };
        let row: [[f64; 3]; 4] = [
            [0.309_803_93, 0.356_862_75, 0.392_156_87],
            [0.309_803_93, 0.360_784_32, 0.396_078_44],
            [0.305_882_36, 0.360_784_32, 0.390_196_08],
            [0.321_568_64, 0.376_470_6, 0.400_000_01],
        ];
        let want = image(4, 2, |x, _| row[x].map(|v| v as f32));
        let got = demosaic(&mosaic, DemosaicMethod::Menon2007);
        assert_close(&got, &want, 1e-6, "Menon2007 example");
    }

    #[test]
    fn parallel_bands_match_one_thread() {
        let img = image(301, 203, |x, y| {
            let (xf, yf) = (x as f32, y as f32);
            [
                0.5 + 0.4 * (0.3 * xf + 0.1 * yf).sin(),
                0.5 + 0.4 * (0.2 * yf).cos(),
                hash((y * 301 + x) as u64),
            ]
        });
        for pattern in CfaPattern::ALL {
            let mosaic = Mosaic::from_rgb(&img, pattern);
            for method in DemosaicMethod::ALL {
                let (mut one, mut many) = (RgbImage::new(1, 1), RgbImage::new(1, 1));
                demosaic_with(&mosaic, method, &mut one, false);
                demosaic_with(&mosaic, method, &mut many, true);
                assert_eq!(one, many, "{method:?} {pattern:?}");
            }
        }
    }

    #[test]
    fn into_reuses_and_resizes_the_output() {
        let big = Mosaic::from_rgb(&chart(), CfaPattern::Grbg);
        let small = Mosaic::from_rgb(&edge_rich(), CfaPattern::Gbrg);
        let mut out = demosaic(&big, DemosaicMethod::Menon2007);
        for method in DemosaicMethod::ALL {
            demosaic_into(&small, method, &mut out);
            assert_eq!(out, demosaic(&small, method));
            demosaic_into(&big, method, &mut out);
            assert_eq!(out, demosaic(&big, method));
        }
    }

    #[test]
    fn quality_ranks_menon_over_malvar_over_bilinear() {
        for (name, truth) in [("edge-rich", edge_rich()), ("chart", chart())] {
            for pattern in CfaPattern::ALL {
                let mosaic = Mosaic::from_rgb(&truth, pattern);
                let [bilinear, malvar, menon] =
                    DemosaicMethod::ALL.map(|m| psnr(&demosaic(&mosaic, m), &truth));
                println!(
                    "PSNR {name} {pattern:?}: bilinear {bilinear:.2} dB, malvar2004 {malvar:.2} dB, \
                     menon2007 {menon:.2} dB"
                );
                assert!(
                    menon >= malvar,
                    "{name} {pattern:?}: Menon {menon} < Malvar {malvar}"
                );
                assert!(
                    malvar > bilinear,
                    "{name} {pattern:?}: Malvar {malvar} ≤ bilinear {bilinear}"
                );
            }
        }
    }
}
