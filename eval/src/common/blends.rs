//! The peers' blending rules that more than one benchmark runs.

use reference::envmap::luminance;

/// DDGI v1.3.7's blend of one texel, in gamma-5 encoded space: hysteresis 0.97, lowered by
/// 0.75 where a channel drops by more than `thresholds.0`, the step damped ×0.25 where the
/// luminance change exceeds `thresholds.1`, and a falling texel's step at least 1/1024.
#[must_use]
pub fn ddgi_blend(prev: [f64; 3], new: [f64; 3], thresholds: (f64, f64)) -> [f64; 3] {
    let enc = |x: [f64; 3]| x.map(|c| c.max(0.0).powf(0.2));
    let (p, r) = (enc(prev), enc(new));
    let mut hysteresis = 0.97f64;
    let max3 = |x: [f64; 3]| x[0].max(x[1]).max(x[2]);
    if max3([p[0] - r[0], p[1] - r[1], p[2] - r[2]]) > thresholds.0 {
        hysteresis = (hysteresis - 0.75).max(0.0);
    }
    let mut delta = [r[0] - p[0], r[1] - p[1], r[2] - p[2]];
    if luminance(delta) > thresholds.1 {
        delta = delta.map(|d| d * 0.25);
    }
    let mut step = delta.map(|d| (1.0 - hysteresis) * d);
    if max3(r) < max3(p) {
        for (s, d) in step.iter_mut().zip(delta) {
            *s = s.abs().max(1.0 / 1024.0).min(d.abs()) * s.signum();
        }
    }
    [p[0] + step[0], p[1] + step[1], p[2] + step[2]].map(|c| c.powi(5))
}
