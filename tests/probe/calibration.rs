//! The documented error-bar calibration of a probe member (`Member::calibration`), written
//! from the docs, for the tests that compare the probe's variances with an f64 model.

use sphere_quadrature::probe::Member;

/// The glossy calibration factor at lobe sharpness `μ`: the member's factors at
/// μ = 7, 22, 102, linear in ln μ between them and constant outside.
pub fn glossy_calibration(m: &Member, mu: f64) -> f64 {
    let c = m.calibration.map(f64::from);
    let nodes = [(7.0f64, c[1]), (22.0, c[2]), (102.0, c[3])];
    if mu <= nodes[0].0 {
        return nodes[0].1;
    }
    if mu >= nodes[2].0 {
        return nodes[2].1;
    }
    let w = nodes.windows(2).find(|w| mu <= w[1].0).unwrap_or(&nodes[1..]);
    let t = (mu / w[0].0).ln() / (w[1].0 / w[0].0).ln();
    w[0].1 + t * (w[1].1 - w[0].1)
}
