//! Equirectangular environment maps and their nearest-pixel radiance function.
//!
//! A W×H map: row v (0 = top) covers polar angles θ ∈ [πv/H, π(v+1)/H] from +z,
//! column u covers azimuths φ ∈ [2πu/W, 2π(u+1)/W]; the pixel centre direction is
//! (sinθ cosφ, sinθ sinφ, cosθ) at θ = π(v + ½)/H, φ = 2π(u + ½)/W. The radiance
//! function of the map is piecewise constant: the value of the pixel whose box contains
//! the direction.

use core::f64::consts::PI;
use std::path::Path;

/// Rec. 709 / sRGB luminance of a linear RGB triple: 0.2126 R + 0.7152 G + 0.0722 B.
pub fn luminance(rgb: [f64; 3]) -> f64 {
    0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]
}

/// An equirectangular environment map with linear RGB radiance per pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvMap {
    /// Number of columns (azimuth samples).
    pub width: usize,
    /// Number of rows (polar-angle samples).
    pub height: usize,
    /// Row-major pixels, row 0 at the top (θ near 0, +z).
    pub pixels: Vec<[f32; 3]>,
}

impl EnvMap {
    /// A map from explicit pixels (row-major, row 0 at the top).
    ///
    /// # Panics
    /// If `pixels.len() != width * height` or a dimension is 0.
    pub fn new(width: usize, height: usize, pixels: Vec<[f32; 3]>) -> Self {
        assert!(width > 0 && height > 0, "empty map");
        assert_eq!(pixels.len(), width * height, "pixel count does not match dimensions");
        EnvMap { width, height, pixels }
    }

    /// A map whose every pixel holds `rgb`.
    pub fn constant(width: usize, height: usize, rgb: [f32; 3]) -> Self {
        Self::new(width, height, vec![rgb; width * height])
    }

    /// A map whose pixels hold `f` evaluated at the pixel-centre directions (rounded to
    /// f32).
    pub fn from_fn(width: usize, height: usize, f: impl Fn([f64; 3]) -> [f64; 3]) -> Self {
        let mut pixels = Vec::with_capacity(width * height);
        let mut m = EnvMap { width, height, pixels: Vec::new() };
        for v in 0..height {
            for u in 0..width {
                let c = f(m.pixel_direction(u, v));
                pixels.push([c[0] as f32, c[1] as f32, c[2] as f32]);
            }
        }
        m.pixels = pixels;
        m
    }

    /// Loads a Radiance RGBE (`.hdr`) file (any format the `image` crate was built with)
    /// as linear RGB f32.
    pub fn load(path: impl AsRef<Path>) -> Result<EnvMap, String> {
        let path = path.as_ref();
        let img = image::ImageReader::open(path)
            .map_err(|e| format!("{}: {e}", path.display()))?
            .with_guessed_format()
            .map_err(|e| format!("{}: {e}", path.display()))?
            .decode()
            .map_err(|e| format!("{}: {e}", path.display()))?
            .into_rgb32f();
        let (w, h) = (img.width() as usize, img.height() as usize);
        if w == 0 || h == 0 {
            return Err(format!("{}: empty image", path.display()));
        }
        let pixels = img.pixels().map(|p| p.0).collect();
        Ok(EnvMap { width: w, height: h, pixels })
    }

    /// Rec. 709 luminance of an RGB triple (same as the free function [`luminance`]).
    pub fn luminance(rgb: [f64; 3]) -> f64 {
        luminance(rgb)
    }

    /// RGB of pixel (u, v) as f64.
    pub fn pixel(&self, u: usize, v: usize) -> [f64; 3] {
        let p = self.pixels[v * self.width + u];
        [p[0] as f64, p[1] as f64, p[2] as f64]
    }

    /// Centre direction of pixel (u, v): θ = π(v + ½)/H, φ = 2π(u + ½)/W.
    pub fn pixel_direction(&self, u: usize, v: usize) -> [f64; 3] {
        let theta = PI * (v as f64 + 0.5) / self.height as f64;
        let phi = 2.0 * PI * (u as f64 + 0.5) / self.width as f64;
        let (st, ct) = theta.sin_cos();
        let (sp, cp) = phi.sin_cos();
        [st * cp, st * sp, ct]
    }

    /// Exact solid angle of any pixel of row v:
    /// (2π/W)(cos(πv/H) − cos(π(v+1)/H)) = (2π/W)·2 sin(π(v+½)/H) sin(π/(2H)).
    pub fn pixel_solid_angle(&self, v: usize) -> f64 {
        let h = self.height as f64;
        let dphi = 2.0 * PI / self.width as f64;
        dphi * 2.0 * (PI * (v as f64 + 0.5) / h).sin() * (PI / (2.0 * h)).sin()
    }

    /// The pixel (u, v) whose box contains the direction of `dir` (normalised first).
    /// Boundaries belong to the pixel with the larger index, except at θ = π and
    /// φ → 2π, which go to the last row and wrap to column 0 respectively.
    pub fn pixel_of(&self, dir: [f64; 3]) -> (usize, usize) {
        let rho = dir[0].hypot(dir[1]);
        let theta = rho.atan2(dir[2]); // [0, π], scale-invariant
        let mut phi = dir[1].atan2(dir[0]); // (−π, π]
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        let v = ((theta / PI * self.height as f64).floor() as usize).min(self.height - 1);
        let mut u = (phi / (2.0 * PI) * self.width as f64).floor() as usize;
        if u >= self.width {
            u -= self.width;
        }
        (u, v)
    }

    /// Radiance of the map in direction `dir`: the pixel containing it (nearest-pixel
    /// lookup; `dir` need not be unit length).
    pub fn radiance(&self, dir: [f64; 3]) -> [f64; 3] {
        let (u, v) = self.pixel_of(dir);
        self.pixel(u, v)
    }

    /// Solid-angle weighted mean radiance per channel: (1/4π) ∫ L dω.
    pub fn mean_radiance(&self) -> [f64; 3] {
        let mut acc = [0.0; 3];
        for v in 0..self.height {
            let mut row = [0.0; 3];
            for u in 0..self.width {
                let p = self.pixel(u, v);
                for c in 0..3 {
                    row[c] += p[c];
                }
            }
            let w = self.pixel_solid_angle(v);
            for c in 0..3 {
                acc[c] += row[c] * w;
            }
        }
        acc.map(|x| x / (4.0 * PI))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    #[test]
    fn solid_angles_sum_to_4pi() {
        for (w, h) in [(512, 256), (64, 32), (7, 5), (1, 1)] {
            let m = EnvMap::constant(w, h, [1.0; 3]);
            let s: f64 = (0..h).map(|v| m.pixel_solid_angle(v) * w as f64).sum();
            assert!((s - 4.0 * PI).abs() < 1e-12, "{w}x{h}: {s}");
            // Against the direct difference of cosines.
            for v in 0..h {
                let a = (PI * v as f64 / h as f64).cos() - (PI * (v + 1) as f64 / h as f64).cos();
                assert!((m.pixel_solid_angle(v) - 2.0 * PI / w as f64 * a).abs() < 1e-15);
            }
            let mean = m.mean_radiance();
            assert!((mean[0] - 1.0).abs() < 1e-14);
        }
    }

    #[test]
    fn lookup_finds_the_pixel_of_every_centre_and_handles_edges() {
        let m = EnvMap::from_fn(512, 256, |d| d);
        for v in 0..256 {
            for u in 0..512 {
                assert_eq!(m.pixel_of(m.pixel_direction(u, v)), (u, v));
            }
        }
        assert_eq!(m.pixel_of([0.0, 0.0, 1.0]), (0, 0));
        assert_eq!(m.pixel_of([0.0, 0.0, -1.0]).1, 255);
        assert_eq!(m.pixel_of([1.0, -1e-300, 0.0]), (0, 128));
        assert_eq!(m.pixel_of([1.0, -1e-9, 0.0]).0, 511);
        assert_eq!(m.pixel_of([-2.0, -0.0, 0.0]), (256, 128));
        assert_eq!(m.pixel_of([0.0, 0.0, 5.0]), (0, 0));
        // Random directions land in the pixel whose box contains them.
        let mut r = Rng::new(2);
        for _ in 0..10_000 {
            let d = r.uniform_sphere();
            let (u, v) = m.pixel_of(crate::vec::scale(d, 0.3));
            let theta = d[2].acos();
            let phi = d[1].atan2(d[0]).rem_euclid(2.0 * PI);
            assert!(theta >= PI * v as f64 / 256.0 - 1e-12);
            assert!(theta <= PI * (v + 1) as f64 / 256.0 + 1e-12);
            assert!(phi >= 2.0 * PI * u as f64 / 512.0 - 1e-12);
            assert!(phi <= 2.0 * PI * (u + 1) as f64 / 512.0 + 1e-12);
            let l = m.radiance(d);
            let c = m.pixel_direction(u, v);
            assert_eq!(l, [c[0] as f32 as f64, c[1] as f32 as f64, c[2] as f32 as f64]);
        }
    }

    #[test]
    fn luminance_weights() {
        assert!((luminance([1.0, 1.0, 1.0]) - 1.0).abs() < 1e-15);
        assert_eq!(luminance([0.0, 1.0, 0.0]), 0.7152);
    }

    #[test]
    fn load_reports_errors() {
        assert!(EnvMap::load("/nonexistent/map.hdr").is_err());
    }

    #[test]
    fn load_roundtrips_a_written_hdr() {
        // Write a tiny Radiance file by hand (uncompressed RGBE scanlines) and read it back.
        let (w, h) = (8usize, 4usize);
        let mut bytes = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n".to_vec();
        bytes.extend(format!("-Y {h} +X {w}\n").as_bytes());
        let mut want = Vec::new();
        for v in 0..h {
            for u in 0..w {
                // Values exactly representable in RGBE: mantissa/256 · 2^(e − 128).
                let m = [(128 + 16 * u) as u8, (128 + 8 * v) as u8, 200u8];
                let e = 129u8 + (v as u8); // scale 2^(e − 136)
                bytes.extend([m[0], m[1], m[2], e]);
                let s = 2f32.powi(e as i32 - 136);
                want.push([m[0] as f32 * s, m[1] as f32 * s, m[2] as f32 * s]);
            }
        }
        let dir = std::env::temp_dir().join(format!("reference-envmap-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("tiny.hdr");
        std::fs::write(&path, &bytes).unwrap();
        let m = EnvMap::load(&path);
        std::fs::remove_dir_all(&dir).ok();
        let m = m.unwrap();
        assert_eq!((m.width, m.height), (w, h));
        for (got, want) in m.pixels.iter().zip(&want) {
            for c in 0..3 {
                // A decoder may add half a mantissa step (≤ 1/256 relative here).
                assert!((got[c] - want[c]).abs() <= want[c] / 200.0, "{got:?} {want:?}");
            }
        }
    }
}
