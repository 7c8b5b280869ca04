//! Fitting convergence rates.

/// Least-squares slope of `ln y` against `ln x`: the fitted exponent `p` of `y ≈ c·xᵖ`.
///
/// ```
/// let xs = [1.0, 2.0, 4.0, 8.0];
/// let ys: Vec<f64> = xs.iter().map(|x: &f64| 3.0 * x.powf(-0.75)).collect();
/// assert!((reference::fit::loglog_slope(&xs, &ys) + 0.75).abs() < 1e-12);
/// ```
#[must_use]
pub fn loglog_slope(xs: &[f64], ys: &[f64]) -> f64 {
    let lx: Vec<f64> = xs.iter().map(|x| x.ln()).collect();
    let ly: Vec<f64> = ys.iter().map(|y| y.ln()).collect();
    let n = lx.len() as f64;
    let (mx, my) = (lx.iter().sum::<f64>() / n, ly.iter().sum::<f64>() / n);
    let sxy: f64 = lx.iter().zip(&ly).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = lx.iter().map(|x| (x - mx) * (x - mx)).sum();
    sxy / sxx
}
