//! The glossy renderer form: Bayesian Monte Carlo of the Phong lobe with the cosine factor,
//! with weights baked per `(N, e)` on a grid of the angle between the normal and the mirror
//! direction (issue #12; generator `gen/glossy.rs`, sets in `tables/glossy.txt`).
//!
//! The integral is `I(n, r) = ∫ L(x)·(e+1)/(2π)·max(0, r·x)ᵉ·max(0, n·x) dx`: the normalised
//! Phong lobe about the mirror direction `r`, with the cosine factor and the horizon at the
//! normal `n`. [`GlossyRenderer::directions`] places the `N`-point hemisphere spherical
//! Fibonacci set morphed onto the lobe (the QMC-SF samples, at phase 0) in the frame whose first
//! axis points from `r` towards `n`; in that frame the kernel matrix is fixed and the weights
//! depend on the query only through `θₙ = acos(r·n)`, so they are baked on 49 nodes of
//! `θₙ ∈ [0, π/2]` graded towards grazing and interpolated quadratically in the node index
//! ([`GlossyRenderer::estimate`], O(N); 196·N bytes per `(N, e)`).
//! `zᵢ` comes from the seed's spherical-Gaussian route (a 5-SG fit of the lobe, SG products,
//! the clamped-cosine integral's f64 generator), so constants are integrated exactly for the
//! fitted lobe (fit error: `tests/glossy.rs`).
//!
//! ```
//! use sphere_quadrature::{bmc::GlossyRenderer, Vec3};
//!
//! let r = GlossyRenderer::<64, 50>::new();
//! let (n, mirror) = (Vec3::Z, Vec3::new(0.6, 0.0, 0.8));
//! let mut dirs = [Vec3::Z; 64];
//! r.directions(n, mirror, &mut dirs)?;
//! // A constant radiance c gives c·∫p (the lobe's cosine-weighted integral).
//! let e = r.estimate(n, mirror, &[2.0f32; 64])?;
//! assert!(e > 1.4 && e < 1.8);
//! # Ok::<(), sphere_quadrature::Error>(())
//! ```
//!
//! # Bad input
//! A zero or non-finite normal or mirror direction gives [`Error::InvalidDirection`]; a mirror
//! direction below the horizon (`r·n < 0`) is treated as grazing (`θₙ = π/2`).

use super::Size;
use crate::error::Error;
use crate::radiance::Radiance;
use crate::sf::FibonacciPoints;
use crate::vec3::Vec3;
use crate::warp::{Frame, Lobe};

/// Nodes of `θₙ = acos(r·n)` over `[0, π/2]`, at `θₙ = (π/2)·sin((π/2)·k/(GRID − 1))`
/// (`gen/glossy.rs` emits tables of `GRID·N` weights).
pub const GRID: usize = 49;

/// Implemented for exactly the sizes `N` whose glossy weights are baked for exponent `E`;
/// sealed.
#[diagnostic::on_unimplemented(
    message = "no glossy Bayesian Monte Carlo weights are baked for `{Self}` and e = {E}",
    label = "this sample count and Phong exponent have no baked weights",
    note = "the baked (N, e) pairs are in tables/glossy.txt"
)]
pub trait GlossySize<const E: u32>: sealed::Sealed<E> {}

pub(crate) mod sealed {
    /// What `build.rs` baked for one `(N, e)`.
    #[derive(Clone, Copy, Debug)]
    pub struct Set {
        /// `GRID·N` weights (f32 bits), node-major.
        pub weights: &'static [u32],
        pub length_scale: f32,
        pub noise: f32,
    }

    pub trait Sealed<const E: u32> {
        const SET: Set;
    }
}

/// The baked `(N, e)` pairs.
pub const BAKED_SETS: &[(usize, u32)] = &crate::tables::GLOSSY_SETS;

/// Flash of all baked glossy weights in bytes (`4·GRID·N` per set; only the sets a program
/// uses are linked).
pub const TABLE_BYTES: usize = {
    let mut sum = 0;
    let mut i = 0;
    while i < BAKED_SETS.len() {
        sum += 4 * GRID * BAKED_SETS[i].0;
        i += 1;
    }
    sum
};

/// Bayesian Monte Carlo of the Phong lobe (exponent `E`) with the cosine factor, from `N`
/// lobe-morphed spherical Fibonacci samples with baked weights. Zero-sized.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GlossyRenderer<const N: usize, const E: u32>
where
    Size<N>: GlossySize<E>;

impl<const N: usize, const E: u32> GlossyRenderer<N, E>
where
    Size<N>: GlossySize<E>,
{
    const SET: sealed::Set = <Size<N> as sealed::Sealed<E>>::SET;

    /// The renderer.
    #[must_use]
    pub const fn new() -> Self {
        Self
    }

    /// The kernel's `(l, σ′)`.
    #[must_use]
    pub const fn hyperparameters() -> (f32, f32) {
        (Self::SET.length_scale, Self::SET.noise)
    }

    /// The lobe frame `(t₁, t₂, r)` with `t₁` towards `n`, and `r·n` clamped to `[0, 1]`.
    fn frame(normal: Vec3, mirror: Vec3) -> Result<([Vec3; 3], f32), Error> {
        let n = normal.try_normalize().ok_or(Error::InvalidDirection)?;
        let r = mirror.try_normalize().ok_or(Error::InvalidDirection)?;
        let c = r.dot(n).clamp(0.0, 1.0);
        let t1 = match (n - r * c).try_normalize() {
            Some(t) => t,
            // n ∥ r: the integrand is symmetric about r, any perpendicular serves.
            None => Frame::from_unit(r).to_world(Vec3::X),
        };
        Ok(([t1, r.cross(t1), r], c))
    }

    /// Writes the `N` sample directions for normal `n` and mirror direction `r` (both
    /// normalised first).
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero or non-finite vector.
    pub fn directions(&self, normal: Vec3, mirror: Vec3, out: &mut [Vec3; N]) -> Result<(), Error> {
        let ([t1, t2, r], _) = Self::frame(normal, mirror)?;
        let set = FibonacciPoints::hemisphere(N)?;
        let lobe = Lobe::Phong(E as f32);
        for (j, slot) in out.iter_mut().enumerate() {
            let (c, s) = lobe.morph(set.one_minus_z(j));
            let (sp, cp) = crate::math::sin_cos_turns(set.phase_of(j));
            *slot = t1 * (s * cp) + t2 * (s * sp) + r * c;
        }
        Ok(())
    }

    /// The three weight rows around `θₙ` and their quadratic interpolation coefficients.
    #[allow(clippy::type_complexity)]
    fn rows(
        normal: Vec3,
        mirror: Vec3,
    ) -> Result<((&'static [u32], &'static [u32], &'static [u32]), [f32; 3]), Error> {
        let (_, c) = Self::frame(normal, mirror)?;
        // Node index k(θₙ) = (GRID − 1)·asin(θₙ/(π/2))/(π/2), θₙ = acos(c).
        let ratio = (crate::math::acos(c) * core::f32::consts::FRAC_2_PI).min(1.0);
        let u = libm::asinf(ratio) * ((GRID - 1) as f32 * core::f32::consts::FRAC_2_PI);
        // Quadratic interpolation through the nearest node and its neighbours.
        let k = (crate::math::floor(u + 0.5) as usize).clamp(1, GRID - 2);
        let f = u - k as f32;
        let w = Self::SET.weights;
        let rows =
            (w.get((k - 1) * N..k * N), w.get(k * N..(k + 1) * N), w.get((k + 1) * N..(k + 2) * N));
        let (Some(a), Some(b), Some(c)) = rows else {
            return Err(Error::InvalidParameter);
        };
        Ok(((a, b, c), [0.5 * f * (f - 1.0), 1.0 - f * f, 0.5 * f * (f + 1.0)]))
    }

    /// The interpolated weights for `(n, r)`, in the order of [`GlossyRenderer::directions`].
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero or non-finite vector.
    pub fn weights(&self, normal: Vec3, mirror: Vec3, out: &mut [f32; N]) -> Result<(), Error> {
        let ((a, b, c), [c0, c1, c2]) = Self::rows(normal, mirror)?;
        for (((o, &a), &b), &c) in out.iter_mut().zip(a).zip(b).zip(c) {
            *o = c0 * f32::from_bits(a) + c1 * f32::from_bits(b) + c2 * f32::from_bits(c);
        }
        Ok(())
    }

    /// `I(n, r) ≈ Σ wⱼ·Yⱼ` from the radiance in each direction of
    /// [`GlossyRenderer::directions`], in order; O(N) (the interpolation is fused into the sum).
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero or non-finite vector.
    pub fn estimate<T: Radiance>(
        &self,
        normal: Vec3,
        mirror: Vec3,
        samples: &[T; N],
    ) -> Result<T, Error> {
        let ((a, b, c), [c0, c1, c2]) = Self::rows(normal, mirror)?;
        // Σ wⱼYⱼ = c₀·Σ aⱼYⱼ + c₁·Σ bⱼYⱼ + c₂·Σ cⱼYⱼ.
        let (mut sa, mut sb, mut sc) = (T::ZERO, T::ZERO, T::ZERO);
        for (((&y, &a), &b), &c) in samples.iter().zip(a).zip(b).zip(c) {
            sa = sa.mul_add(y, f32::from_bits(a));
            sb = sb.mul_add(y, f32::from_bits(b));
            sc = sc.mul_add(y, f32::from_bits(c));
        }
        Ok(sa.scale(c0).add(sb.scale(c1)).add(sc.scale(c2)))
    }
}
