//! The one image comparison the tests use: per pixel the largest difference of the colour
//! channels, and whether any channel (alpha too) differs.

/// How two images of one size differ.
pub struct ImageDiff {
    /// Per pixel, the largest difference of its R, G and B.
    largest: Vec<u8>,
    /// Pixels with any channel different, alpha included.
    differing: usize,
    /// Sum of squared R, G and B differences.
    squared: f64,
}

/// Compares `a` with `b` (same size: a test's bug otherwise, so it panics).
pub fn image_diff(a: &image::RgbaImage, b: &image::RgbaImage) -> ImageDiff {
    assert_eq!(a.dimensions(), b.dimensions(), "images of different sizes");
    let (mut largest, mut differing, mut squared) = (Vec::new(), 0, 0.0);
    for (p, q) in a.pixels().zip(b.pixels()) {
        largest.push((0..3).map(|c| p[c].abs_diff(q[c])).max().unwrap_or(0));
        differing += usize::from(p != q);
        squared += (0..3)
            .map(|c| (p[c] as f64 - q[c] as f64).powi(2))
            .sum::<f64>();
    }
    ImageDiff {
        largest,
        differing,
        squared,
    }
}

impl ImageDiff {
    /// The largest channel difference over every pixel (R, G, B).
    pub fn largest(&self) -> u8 {
        self.largest.iter().copied().max().unwrap_or(0)
    }

    /// Pixels whose largest channel difference exceeds `levels`.
    pub fn over(&self, levels: u8) -> usize {
        self.largest.iter().filter(|&&d| d > levels).count()
    }

    /// Pixels that differ at all (alpha included).
    pub fn differing(&self) -> usize {
        self.differing
    }

    /// Peak signal-to-noise ratio over R, G and B in dB (infinite when equal).
    pub fn psnr(&self) -> f64 {
        let mse = self.squared / (self.largest.len() * 3) as f64;
        if mse == 0.0 {
            f64::INFINITY
        } else {
            10.0 * (255.0f64 * 255.0 / mse).log10()
        }
    }
}
