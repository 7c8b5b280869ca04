//! One call shape for `FootprintRenderer<N, B>` in generic test code: the normal and the
//! mirror direction, which the irradiance renderer does not take (and these calls drop).

use sphere_quadrature::bmc::footprint::{Diffuse, FootprintRenderer, FootprintSize, Phong};
use sphere_quadrature::{Error, Estimate, Radiance, Size, Vec3};

/// The footprint renderer's calls for a normal `n` and mirror direction `r`.
#[allow(dead_code)] // each test binary uses some of the calls
pub trait Lookups<const N: usize> {
    /// Whether the renderer takes the mirror direction.
    const MIRROR: bool;
    fn fill(&self, n: Vec3, r: Vec3, out: &mut [Vec3; N]) -> Result<(), Error>;
    fn weights_for(&self, n: Vec3, r: Vec3, out: &mut [f32; N]) -> Result<(), Error>;
    fn estimate_for<T: Radiance>(&self, n: Vec3, r: Vec3, y: &[T; N]) -> Result<T, Error>;
    fn estimate_with_variance_for<T: Radiance>(
        &self,
        n: Vec3,
        r: Vec3,
        y: &[T; N],
    ) -> Result<Estimate<T>, Error>;
}

/// Irradiance: `r` is not an argument of the renderer; a bad `r` is still refused here, as
/// a caller that computes it would refuse it.
impl<const N: usize> Lookups<N> for FootprintRenderer<N, Diffuse>
where
    Size<N>: FootprintSize<Diffuse>,
{
    const MIRROR: bool = false;
    fn fill(&self, n: Vec3, r: Vec3, out: &mut [Vec3; N]) -> Result<(), Error> {
        r.try_normalize().ok_or(Error::InvalidDirection)?;
        self.fill_directions(n, out)
    }
    fn weights_for(&self, n: Vec3, r: Vec3, out: &mut [f32; N]) -> Result<(), Error> {
        n.try_normalize().and(r.try_normalize()).ok_or(Error::InvalidDirection)?;
        self.weights(out)
    }
    fn estimate_for<T: Radiance>(&self, n: Vec3, r: Vec3, y: &[T; N]) -> Result<T, Error> {
        n.try_normalize().and(r.try_normalize()).ok_or(Error::InvalidDirection)?;
        self.estimate(y)
    }
    fn estimate_with_variance_for<T: Radiance>(
        &self,
        n: Vec3,
        r: Vec3,
        y: &[T; N],
    ) -> Result<Estimate<T>, Error> {
        n.try_normalize().and(r.try_normalize()).ok_or(Error::InvalidDirection)?;
        self.estimate_with_variance(y)
    }
}

impl<const N: usize, const E: u32> Lookups<N> for FootprintRenderer<N, Phong<E>>
where
    Size<N>: FootprintSize<Phong<E>>,
{
    const MIRROR: bool = true;
    fn fill(&self, n: Vec3, r: Vec3, out: &mut [Vec3; N]) -> Result<(), Error> {
        self.fill_directions(n, r, out)
    }
    fn weights_for(&self, n: Vec3, r: Vec3, out: &mut [f32; N]) -> Result<(), Error> {
        self.weights(n, r, out)
    }
    fn estimate_for<T: Radiance>(&self, n: Vec3, r: Vec3, y: &[T; N]) -> Result<T, Error> {
        self.estimate(n, r, y)
    }
    fn estimate_with_variance_for<T: Radiance>(
        &self,
        n: Vec3,
        r: Vec3,
        y: &[T; N],
    ) -> Result<Estimate<T>, Error> {
        self.estimate_with_variance(n, r, y)
    }
}
