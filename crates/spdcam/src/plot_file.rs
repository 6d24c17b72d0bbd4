//! Writes a plot made as SVG to the file a user named: SVG as it is, PNG rasterised with its
//! text in DejaVu Sans embedded in the program, so a PNG has its labels on any machine.

use anyhow::{bail, Context, Result};
use resvg::{tiny_skia, usvg};
use spdcam_core::fsio;
use std::path::Path;

/// PNG pixels per SVG unit: sharp on high-density screens.
const PNG_SCALE: f32 = 2.0;

/// Whether the plot goes to PNG (else SVG); an error for any other file name, so a command
/// can check before it writes anything.
pub fn plot_is_png(path: &Path) -> Result<bool> {
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    match extension.as_deref() {
        Some("svg") => Ok(false),
        Some("png") => Ok(true),
        _ => bail!(
            "{}: a plot is written as .svg or .png; name the file so",
            path.display()
        ),
    }
}

/// Writes `svg` to `path` (atomically): `.svg` as it is, `.png` rasterised.
pub fn write_plot(path: &Path, svg: &str) -> Result<()> {
    let bytes = if plot_is_png(path)? {
        rasterise(svg)?
    } else {
        svg.as_bytes().to_vec()
    };
    fsio::write_atomic(path, &bytes)?;
    Ok(())
}

/// The SVG drawn on a white background, as PNG bytes.
fn rasterise(svg: &str) -> Result<Vec<u8>> {
    let mut options = usvg::Options::default();
    let fonts = options.fontdb_mut();
    fonts.load_font_data(dejavu::sans::regular().to_vec());
    fonts.set_sans_serif_family("DejaVu Sans");
    fonts.set_serif_family("DejaVu Sans");
    let tree = usvg::Tree::from_str(svg, &options).context("reading the plot's SVG")?;
    let size = tree.size();
    let width = (size.width() * PNG_SCALE).ceil() as u32;
    let height = (size.height() * PNG_SCALE).ceil() as u32;
    let mut pixmap = tiny_skia::Pixmap::new(width.max(1), height.max(1))
        .context("the plot is too large to rasterise")?;
    pixmap.fill(tiny_skia::Color::WHITE);
    resvg::render(
        &tree,
        tiny_skia::Transform::from_scale(PNG_SCALE, PNG_SCALE),
        &mut pixmap.as_mut(),
    );
    pixmap.encode_png().context("encoding the plot as PNG")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn png_plots_are_rasterised_and_other_names_refused() {
        let dir = std::env::temp_dir().join("spdcam-plot-file-test");
        std::fs::create_dir_all(&dir).unwrap();
        let svg = r#"<svg xmlns="http://www.w3.org/2000/svg" width="40" height="20"><rect x="0" y="0" width="20" height="20" fill="rgb(255,0,0)"/></svg>"#;
        let png = dir.join("p.png");
        write_plot(&png, svg).unwrap();
        let image = image::open(&png).unwrap().to_rgb8();
        assert_eq!(image.dimensions(), (80, 40));
        assert_eq!(image.get_pixel(10, 10).0, [255, 0, 0]);
        assert_eq!(image.get_pixel(70, 30).0, [255, 255, 255]);
        let err = write_plot(&dir.join("p.pdf"), svg).unwrap_err().to_string();
        assert!(err.contains(".svg or .png"), "{err}");
        assert!(!dir.join("p.pdf").exists());
        std::fs::remove_dir_all(&dir).ok();
    }

    /// Dark pixels of `svg` rasterised.
    fn ink(svg: &str) -> usize {
        let png = rasterise(svg).unwrap();
        let image = image::load_from_memory(&png).unwrap().to_luma8();
        image.pixels().filter(|p| p.0[0] < 128).count()
    }

    #[test]
    fn png_plots_carry_their_text() {
        let text = r#"<svg xmlns="http://www.w3.org/2000/svg" width="200" height="40"><text x="5" y="30" font-family="sans-serif" font-size="24">wavelength</text></svg>"#;
        let blank = r#"<svg xmlns="http://www.w3.org/2000/svg" width="200" height="40"></svg>"#;
        assert_eq!(ink(blank), 0);
        // "wavelength" at 24 px, doubled by PNG_SCALE, inks thousands of pixels.
        assert!(ink(text) > 1000, "text drew {} dark pixels", ink(text));
    }
}
