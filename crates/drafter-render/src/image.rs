//! RGBA8 images read back from the GPU: box-filter down-sampling, PNG in and out, and the
//! difference measure golden-image tests use.

use std::io::Cursor;

/// An 8-bit RGBA image, rows top to bottom.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    /// `width × height × 4` bytes.
    pub rgba: Vec<u8>,
}

/// Why a PNG could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum PngError {
    #[error("PNG decoding: {0}")]
    Decode(#[from] png::DecodingError),
    #[error("PNG encoding: {0}")]
    Encode(#[from] png::EncodingError),
    #[error("unsupported PNG layout: {0}")]
    Unsupported(String),
}

/// How two images differ (golden-image comparison).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageDiff {
    /// Mean absolute difference over all RGB channels, in [0, 1].
    pub mean_abs: f64,
    /// Fraction of pixels where some channel differs by more than the level threshold.
    pub fraction_over: f64,
    /// Largest channel difference, in levels (0–255).
    pub max_levels: u8,
}

impl Image {
    /// Averages `factor × factor` blocks (the supersampling resolve). `factor` 1 returns a copy.
    pub fn downsample(&self, factor: u32) -> Image {
        if factor <= 1 {
            return self.clone();
        }
        let (w, h) = (self.width / factor, self.height / factor);
        let mut rgba = Vec::with_capacity((w * h * 4) as usize);
        let n = factor * factor;
        for y in 0..h {
            for x in 0..w {
                let mut sum = [0u32; 4];
                for dy in 0..factor {
                    for dx in 0..factor {
                        let i = (((y * factor + dy) * self.width + x * factor + dx) * 4) as usize;
                        for (c, s) in sum.iter_mut().enumerate() {
                            *s += u32::from(self.rgba[i + c]);
                        }
                    }
                }
                rgba.extend(sum.iter().map(|s| ((s + n / 2) / n) as u8));
            }
        }
        Image { width: w, height: h, rgba }
    }

    /// Encodes as an 8-bit RGB PNG (alpha is always opaque here, so it is dropped).
    pub fn to_png(&self) -> Result<Vec<u8>, PngError> {
        let mut out = Vec::new();
        {
            let mut encoder = png::Encoder::new(&mut out, self.width, self.height);
            encoder.set_color(png::ColorType::Rgb);
            encoder.set_depth(png::BitDepth::Eight);
            encoder.set_compression(png::Compression::High);
            let mut writer = encoder.write_header()?;
            let rgb: Vec<u8> = self.rgba.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect();
            writer.write_image_data(&rgb)?;
            writer.finish()?;
        }
        Ok(out)
    }

    /// Decodes an 8-bit RGB or RGBA PNG.
    pub fn from_png(bytes: &[u8]) -> Result<Image, PngError> {
        let mut decoder = png::Decoder::new(Cursor::new(bytes));
        decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
        let mut reader = decoder.read_info()?;
        let size = reader.output_buffer_size().ok_or_else(|| PngError::Unsupported("image too large".into()))?;
        let mut buffer = vec![0; size];
        let info = reader.next_frame(&mut buffer)?;
        let pixels = (info.width * info.height) as usize;
        let rgba = match info.color_type {
            png::ColorType::Rgb => buffer[..pixels * 3].chunks_exact(3).flat_map(|p| [p[0], p[1], p[2], 255]).collect(),
            png::ColorType::Rgba => buffer[..pixels * 4].to_vec(),
            png::ColorType::Grayscale => buffer[..pixels].iter().flat_map(|&g| [g, g, g, 255]).collect(),
            other => return Err(PngError::Unsupported(format!("{other:?}"))),
        };
        Ok(Image { width: info.width, height: info.height, rgba })
    }

    /// Differences over RGB; `None` when the sizes differ. A pixel counts in
    /// [`ImageDiff::fraction_over`] when any channel differs by more than `level_threshold`.
    pub fn diff(&self, other: &Image, level_threshold: u8) -> Option<ImageDiff> {
        if (self.width, self.height) != (other.width, other.height) || self.rgba.len() != other.rgba.len() {
            return None;
        }
        let mut sum = 0u64;
        let mut over = 0usize;
        let mut max = 0u8;
        for (a, b) in self.rgba.chunks_exact(4).zip(other.rgba.chunks_exact(4)) {
            let mut pixel_max = 0u8;
            for c in 0..3 {
                let d = a[c].abs_diff(b[c]);
                sum += u64::from(d);
                pixel_max = pixel_max.max(d);
            }
            max = max.max(pixel_max);
            over += usize::from(pixel_max > level_threshold);
        }
        let pixels = (self.width as usize * self.height as usize).max(1);
        Some(ImageDiff {
            mean_abs: sum as f64 / (pixels as f64 * 3.0 * 255.0),
            fraction_over: over as f64 / pixels as f64,
            max_levels: max,
        })
    }

    /// The RGB of pixel (x, y).
    pub fn pixel(&self, x: u32, y: u32) -> [u8; 3] {
        let i = ((y * self.width + x) * 4) as usize;
        [self.rgba[i], self.rgba[i + 1], self.rgba[i + 2]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn png_round_trip_and_diff() {
        let rgba: Vec<u8> = (0..6 * 4 * 4).map(|i| if i % 4 == 3 { 255 } else { (i * 7 % 256) as u8 }).collect();
        let image = Image { width: 6, height: 4, rgba };
        let back = Image::from_png(&image.to_png().unwrap()).unwrap();
        assert_eq!(back, image);
        let d = image.diff(&back, 8).unwrap();
        assert_eq!((d.mean_abs, d.fraction_over, d.max_levels), (0.0, 0.0, 0));
        let mut other = image.clone();
        other.rgba[0] = other.rgba[0].wrapping_add(20);
        let d = image.diff(&other, 8).unwrap();
        assert_eq!(d.max_levels, 20);
        assert!((d.fraction_over - 1.0 / 24.0).abs() < 1e-12);
        assert!(image.diff(&image.downsample(2), 8).is_none());
    }

    #[test]
    fn downsample_averages_blocks() {
        let image = Image {
            width: 2,
            height: 2,
            rgba: vec![0, 0, 0, 255, 255, 255, 255, 255, 0, 0, 0, 255, 255, 255, 255, 255],
        };
        let small = image.downsample(2);
        assert_eq!((small.width, small.height), (1, 1));
        assert_eq!(small.rgba, vec![128, 128, 128, 255]);
    }
}
