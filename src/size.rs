//! Sample counts as types: the one type every baked table's sealed bound is implemented for.

/// A sample count as a type, for the bounds that admit the baked sizes only
/// ([`BakedSize`](crate::bmc::BakedSize), [`ProbeSize`](crate::probe::ProbeSize) and the
/// renderers').
///
/// # Examples
/// ```
/// use sphere_quadrature::bmc::{BakedSize, Renderer, Size};
///
/// // `Size<N>` carries N into trait bounds; the bound admits the baked sizes only.
/// fn weight_sum<const N: usize>() -> f32
/// where
///     Size<N>: BakedSize,
/// {
///     Renderer::<N>::weights().iter().sum()
/// }
/// assert!((weight_sum::<16>() - 1.0).abs() < 1e-5);
/// assert!((weight_sum::<256>() - 1.0).abs() < 1e-5);
/// ```
#[derive(Clone, Copy, Debug)]
pub struct Size<const N: usize>;
