//! The Cornell box as published, and a path tracer of the radiance a probe's ray sees.
//!
//! Geometry: the Cornell University Program of Computer Graphics, "Cornell Box Data",
//! <https://www.graphics.cornell.edu/online/box/data.html> (coordinates in millimetres, taken
//! here in metres): floor, ceiling, back wall, the left (red) and right (green) walls, the short
//! and the tall block (five faces each; their bottoms lie on the floor), and the light. The box
//! has no front wall: a ray leaving through the front sees nothing (radiance 0).
//!
//! Simplifications, all stated in the report:
//! - each published quad is the two triangles `(v0, v1, v2)` and `(v0, v2, v3)` of its four
//!   vertices as given (the walls are slightly non-planar and non-rectangular in the data:
//!   the floor's corners at x = 552.8 and 549.6 mm, the ceiling's at 556.0);
//! - the light (published at the ceiling's height, y = 548.8 mm) is placed 0.1 mm below it,
//!   so that a ray meets the light before the ceiling; it emits downwards only and reflects
//!   nothing;
//! - reflectances are RGB, not the published spectra: white (0.725, 0.71, 0.68), red
//!   (0.63, 0.065, 0.05), green (0.14, 0.45, 0.091), the values of the RGB Cornell box scenes
//!   renderers ship; the light's radiance is (17, 12, 4) before the benchmark's scale. All
//!   surfaces are Lambertian.
//!
//! Radiance at a ray's first hit: the emission there, plus direct light from every light
//! that is on (one uniformly sampled point per light, with a shadow ray), plus indirect
//! light, path traced: cosine-weighted bounces, each with the same direct-light estimate,
//! continued with Russian roulette (survival probability the surface's largest reflectance,
//! at most 16 bounces). Intersections are exact ray–triangle tests (Möller–Trumbore) over all
//! triangles, with a bounding-box test per block.

use reference::rng::Rng;

/// A point or direction in metres.
pub type V = [f64; 3];

fn sub(a: V, b: V) -> V {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn add(a: V, b: V) -> V {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn mul(a: V, s: f64) -> V {
    [a[0] * s, a[1] * s, a[2] * s]
}
/// `a · b`.
pub fn dot(a: V, b: V) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: V, b: V) -> V {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
fn normalize(a: V) -> V {
    mul(a, 1.0 / dot(a, a).sqrt())
}
fn mm(p: [f64; 3]) -> V {
    p.map(|c| c / 1000.0)
}

/// The published quads, in millimetres (vertex order as published).
pub const FLOOR: [[f64; 3]; 4] =
    [[552.8, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 559.2], [549.6, 0.0, 559.2]];
pub const CEILING: [[f64; 3]; 4] =
    [[556.0, 548.8, 0.0], [556.0, 548.8, 559.2], [0.0, 548.8, 559.2], [0.0, 548.8, 0.0]];
pub const BACK_WALL: [[f64; 3]; 4] =
    [[549.6, 0.0, 559.2], [0.0, 0.0, 559.2], [0.0, 548.8, 559.2], [556.0, 548.8, 559.2]];
pub const RIGHT_WALL: [[f64; 3]; 4] =
    [[0.0, 0.0, 559.2], [0.0, 0.0, 0.0], [0.0, 548.8, 0.0], [0.0, 548.8, 559.2]];
pub const LEFT_WALL: [[f64; 3]; 4] =
    [[552.8, 0.0, 0.0], [549.6, 0.0, 559.2], [556.0, 548.8, 559.2], [556.0, 548.8, 0.0]];
/// The light: published at y = 548.8, placed 0.1 mm below the ceiling.
pub const LIGHT: [[f64; 3]; 4] =
    [[343.0, 548.7, 227.0], [343.0, 548.7, 332.0], [213.0, 548.7, 332.0], [213.0, 548.7, 227.0]];
/// The blocks' footprints (x, z) and heights: the published top faces.
pub const SHORT_BLOCK: ([[f64; 2]; 4], f64) =
    ([[130.0, 65.0], [82.0, 225.0], [240.0, 272.0], [290.0, 114.0]], 165.0);
pub const TALL_BLOCK: ([[f64; 2]; 4], f64) =
    ([[423.0, 247.0], [265.0, 296.0], [314.0, 456.0], [472.0, 406.0]], 330.0);
/// The `block-moved` event: the tall block 10 cm towards the back wall (+z; 3.2 mm from it).
pub const BLOCK_SHIFT_MM: f64 = 100.0;
/// The second light of the `corner-light` event: 8 × 8 cm on the floor (1 mm above it) in the
/// back corner by the green wall, facing up, of the main light's radiance.
pub const CORNER_LIGHT: [[f64; 3]; 4] =
    [[20.0, 1.0, 459.0], [20.0, 1.0, 539.0], [100.0, 1.0, 539.0], [100.0, 1.0, 459.0]];

pub const WHITE: V = [0.725, 0.71, 0.68];
pub const RED: V = [0.63, 0.065, 0.05];
pub const GREEN: V = [0.14, 0.45, 0.091];
/// The `wall-blue` event's left wall: the red's channels reversed.
pub const BLUE: V = [0.05, 0.065, 0.63];
pub const EMISSION: V = [17.0, 12.0, 4.0];

/// What is on and where: one state of the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Setup {
    /// The main light's scale (0: off).
    pub main: f64,
    pub corner_light: bool,
    pub block_moved: bool,
    pub blue_wall: bool,
}

impl Setup {
    pub const BASE: Self =
        Self { main: 1.0, corner_light: false, block_moved: false, blue_wall: false };
}

#[derive(Clone, Copy)]
struct Tri {
    v0: V,
    e1: V,
    e2: V,
    /// `e1 × e2`, and the dual vectors `a1 = (e2 × g)/|g|²`, `a2 = (g × e1)/|g|²`: a point `q`
    /// of the plane is `v0 + u·e1 + v·e2` with `u = a1·(q − v0)`, `v = a2·(q − v0)`.
    g: V,
    a1: V,
    a2: V,
    /// The unit normal on the side rays come from (into the box, out of a block).
    n: V,
    /// Reflectance; an emitter's is 0.
    rho: V,
    /// Radiance emitted on the normal's side.
    emit: V,
}

/// A light to sample: a parallelogram `corner + u·e1 + v·e2`.
#[derive(Clone, Copy)]
struct Light {
    corner: V,
    e1: V,
    e2: V,
    n: V,
    area: f64,
    emit: V,
}

/// A group of triangles behind a bounding box (the walls' group has none).
struct Group {
    lo: V,
    hi: V,
    tris: Vec<Tri>,
}

/// The scene of one setup, its lights scaled by `scale`.
pub struct Scene {
    groups: Vec<Group>,
    lights: Vec<Light>,
    /// Whether any light is on (else every ray sees 0).
    lit: bool,
}

/// Rays start this far off a surface (m).
const EPS: f64 = 1e-7;

fn quad(q: &[[f64; 3]; 4], inside: V, outward: bool, rho: V, emit: V) -> [Tri; 2] {
    let p = q.map(mm);
    let tri = |a: V, b: V, c: V| {
        let (e1, e2) = (sub(b, a), sub(c, a));
        let mut n = normalize(cross(e1, e2));
        // Face the interior point (walls) or away from it (blocks).
        let towards = dot(n, sub(inside, a)) > 0.0;
        if towards == outward {
            n = mul(n, -1.0);
        }
        let g = cross(e1, e2);
        let g2 = dot(g, g);
        let (a1, a2) = (mul(cross(e2, g), 1.0 / g2), mul(cross(g, e1), 1.0 / g2));
        Tri { v0: a, e1, e2, g, a1, a2, n, rho, emit }
    };
    [tri(p[0], p[1], p[2]), tri(p[0], p[2], p[3])]
}

/// A block's five faces (top and sides) from its footprint and height, in millimetres.
fn block(footprint: &[[f64; 2]; 4], height: f64, dz: f64) -> Group {
    let f: Vec<[f64; 2]> = footprint.iter().map(|p| [p[0], p[1] + dz]).collect();
    let centre = [
        f.iter().map(|p| p[0]).sum::<f64>() / 4.0,
        height / 2.0,
        f.iter().map(|p| p[1]).sum::<f64>() / 4.0,
    ];
    let mut tris = Vec::new();
    let top = [0, 1, 2, 3].map(|i| [f[i][0], height, f[i][1]]);
    tris.extend(quad(&top, mm(centre), true, WHITE, [0.0; 3]));
    for i in 0..4 {
        let (a, b) = (f[i], f[(i + 1) % 4]);
        let side =
            [[a[0], 0.0, a[1]], [a[0], height, a[1]], [b[0], height, b[1]], [b[0], 0.0, b[1]]];
        tris.extend(quad(&side, mm(centre), true, WHITE, [0.0; 3]));
    }
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for t in &tris {
        for p in [t.v0, add(t.v0, t.e1), add(t.v0, t.e2)] {
            for c in 0..3 {
                lo[c] = lo[c].min(p[c] - 1e-6);
                hi[c] = hi[c].max(p[c] + 1e-6);
            }
        }
    }
    Group { lo, hi, tris }
}

fn light(q: &[[f64; 3]; 4], n: V, emit: V) -> Light {
    let p = q.map(mm);
    let (e1, e2) = (sub(p[1], p[0]), sub(p[3], p[0]));
    Light { corner: p[0], e1, e2, n, area: dot(cross(e1, e2), cross(e1, e2)).sqrt(), emit }
}

/// The middle of the box (m): the walls face it.
pub const CENTRE: V = [0.278, 0.2744, 0.2796];

impl Scene {
    /// The scene of `setup`, every emission times `scale`.
    pub fn new(setup: Setup, scale: f64) -> Self {
        let none = [0.0; 3];
        let mut walls = Vec::new();
        walls.extend(quad(&FLOOR, CENTRE, false, WHITE, none));
        walls.extend(quad(&CEILING, CENTRE, false, WHITE, none));
        walls.extend(quad(&BACK_WALL, CENTRE, false, WHITE, none));
        walls.extend(quad(&RIGHT_WALL, CENTRE, false, GREEN, none));
        let left = if setup.blue_wall { BLUE } else { RED };
        walls.extend(quad(&LEFT_WALL, CENTRE, false, left, none));
        let main = mul(EMISSION, setup.main * scale);
        walls.extend(quad(&LIGHT, CENTRE, false, none, main));
        let mut lights = Vec::new();
        if setup.main > 0.0 {
            lights.push(light(&LIGHT, [0.0, -1.0, 0.0], main));
        }
        if setup.corner_light {
            let emit = mul(EMISSION, scale);
            // Facing up: its normal points into the box.
            walls.extend(quad(&CORNER_LIGHT, CENTRE, false, none, emit));
            lights.push(light(&CORNER_LIGHT, [0.0, 1.0, 0.0], emit));
        }
        let dz = if setup.block_moved { BLOCK_SHIFT_MM } else { 0.0 };
        let groups = vec![
            Group { lo: [f64::NEG_INFINITY; 3], hi: [f64::INFINITY; 3], tris: walls },
            block(&SHORT_BLOCK.0, SHORT_BLOCK.1, 0.0),
            block(&TALL_BLOCK.0, TALL_BLOCK.1, dz),
        ];
        let lit = !lights.is_empty();
        Self { groups, lights, lit }
    }

    /// The nearest hit along `d` from `o` within `t_max`: distance and triangle; with `any`,
    /// the first found.
    fn hit(&self, o: V, d: V, t_max: f64) -> Option<(f64, &Tri)> {
        self.cast(o, d, t_max, false)
    }

    fn cast(&self, o: V, d: V, t_max: f64, any: bool) -> Option<(f64, &Tri)> {
        let mut best: Option<(f64, &Tri)> = None;
        let mut t_best = t_max;
        let inv = d.map(|c| 1.0 / c);
        for g in &self.groups {
            if g.lo[0].is_finite() && !slab(o, inv, g.lo, g.hi, t_best) {
                continue;
            }
            for tri in &g.tris {
                // The plane first, then the barycentric coordinates of the point on it.
                let den = dot(d, tri.g);
                if den.abs() < 1e-14 {
                    continue;
                }
                let t = dot(sub(tri.v0, o), tri.g) / den;
                if !(t > 1e-9 && t < t_best) {
                    continue;
                }
                let q = sub(add(o, mul(d, t)), tri.v0);
                let u = dot(q, tri.a1);
                if !(0.0..=1.0).contains(&u) {
                    continue;
                }
                let v = dot(q, tri.a2);
                if v < 0.0 || u + v > 1.0 {
                    continue;
                }
                t_best = t;
                best = Some((t, tri));
                if any {
                    return best;
                }
            }
        }
        best
    }

    /// The direct light at `x` (normal `n`, reflectance `rho`) from every light, one sample each.
    fn direct(&self, x: V, n: V, rho: V, rng: &mut Rng) -> V {
        let mut out = [0.0; 3];
        for l in &self.lights {
            let (u, v) = (rng.next_f64(), rng.next_f64());
            let y = add(l.corner, add(mul(l.e1, u), mul(l.e2, v)));
            let o = add(x, mul(n, EPS));
            let w = sub(y, o);
            let d2 = dot(w, w);
            let d = d2.sqrt();
            let w = mul(w, 1.0 / d);
            let (cx, cl) = (dot(n, w), -dot(l.n, w));
            if cx <= 0.0 || cl <= 0.0 {
                continue;
            }
            // Occluded if anything is hit before the light (the light itself is hit at d).
            if self.cast(o, w, d - 1e-6, true).is_some() {
                continue;
            }
            let g = cx * cl * l.area / d2 / std::f64::consts::PI;
            for c in 0..3 {
                out[c] += rho[c] * l.emit[c] * g;
            }
        }
        out
    }

    /// The radiance a ray from `o` along unit `d` sees at its first hit (module docs).
    pub fn radiance(&self, o: V, d: V, rng: &mut Rng) -> V {
        if !self.lit {
            return [0.0; 3];
        }
        let Some((t, tri)) = self.hit(o, d, f64::INFINITY) else { return [0.0; 3] };
        let mut out = if dot(d, tri.n) < 0.0 { tri.emit } else { [0.0; 3] };
        let mut throughput = [1.0; 3];
        let (mut x, mut n, mut rho) = (add(o, mul(d, t)), tri.n, tri.rho);
        let mut dir = d;
        for _ in 0..16 {
            if dot(dir, n) > 0.0 {
                n = mul(n, -1.0);
            }
            let survive = rho[0].max(rho[1]).max(rho[2]);
            if survive <= 0.0 {
                break;
            }
            let direct = self.direct(x, n, rho, rng);
            for c in 0..3 {
                out[c] += throughput[c] * direct[c];
            }
            if rng.next_f64() >= survive {
                break;
            }
            for c in 0..3 {
                throughput[c] *= rho[c] / survive;
            }
            let local = rng.cosine_hemisphere();
            dir = frame(n, local);
            let o2 = add(x, mul(n, EPS));
            let Some((t, tri)) = self.hit(o2, dir, f64::INFINITY) else { break };
            // Emission met by a bounce is counted by the direct-light estimate already.
            x = add(o2, mul(dir, t));
            n = tri.n;
            rho = tri.rho;
        }
        out
    }
}

/// Whether the ray `o + t·d` (`inv` = 1/d) meets the box `[lo, hi]` at some `0 ≤ t < t_max`.
fn slab(o: V, inv: V, lo: V, hi: V, t_max: f64) -> bool {
    let (mut t0, mut t1) = (0.0f64, t_max);
    for c in 0..3 {
        let a = (lo[c] - o[c]) * inv[c];
        let b = (hi[c] - o[c]) * inv[c];
        let (a, b) = if a < b { (a, b) } else { (b, a) };
        // NaN (a zero component with o on a slab's face) compares false: keeps the box.
        if a > t0 {
            t0 = a;
        }
        if b < t1 {
            t1 = b;
        }
    }
    t0 <= t1
}

/// `local` (z up) turned to the frame whose z is the unit `n`.
fn frame(n: V, local: V) -> V {
    let a = if n[0].abs() > 0.9 { [0.0, 1.0, 0.0] } else { [1.0, 0.0, 0.0] };
    let t = normalize(cross(a, n));
    let b = cross(n, t);
    add(add(mul(t, local[0]), mul(b, local[1])), mul(n, local[2]))
}

/// A point strictly inside a block of `setup` (or within `margin` m of it).
#[cfg(test)]
pub fn in_block(p: V, setup: Setup, margin: f64) -> bool {
    let dz = if setup.block_moved { BLOCK_SHIFT_MM } else { 0.0 };
    [(SHORT_BLOCK, 0.0), (TALL_BLOCK, dz)]
        .iter()
        .any(|((f, h), dz)| penetration(p, f, *h, *dz, margin).is_some())
}

/// How to leave a block (footprint `f`, height `h` mm, shifted `dz` mm) grown by `margin` m:
/// the outward unit direction and distance, if `p` is inside.
fn penetration(p: V, f: &[[f64; 2]; 4], h: f64, dz: f64, margin: f64) -> Option<(V, f64)> {
    let pts: Vec<[f64; 2]> = f.iter().map(|q| [q[0] / 1000.0, (q[1] + dz) / 1000.0]).collect();
    let cx = pts.iter().map(|q| q[0]).sum::<f64>() / 4.0;
    let cz = pts.iter().map(|q| q[1]).sum::<f64>() / 4.0;
    let mut best = (h / 1000.0 + margin - p[1], [0.0, 1.0, 0.0]);
    if best.0 <= 0.0 {
        return None;
    }
    for i in 0..4 {
        let (a, b) = (pts[i], pts[(i + 1) % 4]);
        let e = [b[0] - a[0], b[1] - a[1]];
        let len = (e[0] * e[0] + e[1] * e[1]).sqrt();
        let mut nx = [e[1] / len, -e[0] / len];
        if nx[0] * (cx - a[0]) + nx[1] * (cz - a[1]) > 0.0 {
            nx = [-nx[0], -nx[1]];
        }
        let out = nx[0] * (p[0] - a[0]) + nx[1] * (p[2] - a[1]);
        let depth = margin - out;
        if depth <= 0.0 {
            return None;
        }
        // Only a way out that stays 2 cm inside the box's walls.
        let (x, z) = (p[0] + nx[0] * depth, p[2] + nx[1] * depth);
        if depth < best.0 && (0.02..0.536).contains(&x) && (0.02..0.539).contains(&z) {
            best = (depth, [nx[0], 0.0, nx[1]]);
        }
    }
    Some((best.1, best.0))
}

/// The 4 × 4 × 4 probe grid: at 0.1, 0.37, 0.63 and 0.9 of the box's extent per axis (the
/// outer layers 5.5 cm from the walls), a probe inside a block (either position of the tall
/// one) or within 3 cm of it moved out through the nearest face to 3 cm off it, as DDGI
/// relocates probes out of geometry.
pub fn probe_grid() -> Vec<V> {
    const AT: [f64; 4] = [0.1, 0.37, 0.63, 0.9];
    const MARGIN: f64 = 0.03;
    let extent = [0.556, 0.5488, 0.5592];
    let mut out = Vec::new();
    for &fx in &AT {
        for &fy in &AT {
            for &fz in &AT {
                let mut p = [fx * extent[0], fy * extent[1], fz * extent[2]];
                for _ in 0..3 {
                    for (block, dz) in
                        [(SHORT_BLOCK, 0.0), (TALL_BLOCK, 0.0), (TALL_BLOCK, BLOCK_SHIFT_MM)]
                    {
                        if let Some((dir, depth)) = penetration(p, &block.0, block.1, dz, MARGIN) {
                            p = add(p, mul(dir, depth + 1e-6));
                        }
                    }
                }
                out.push(p);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn probes_lie_in_the_box_outside_every_block() {
        let probes = probe_grid();
        assert_eq!(probes.len(), 64);
        for p in &probes {
            for moved in [false, true] {
                let s = Setup { block_moved: moved, ..Setup::BASE };
                assert!(!in_block(*p, s, 0.029), "{p:?} in a block (moved {moved})");
            }
            assert!(p[0] > 0.02 && p[0] < 0.53 && p[1] > 0.02 && p[1] < 0.52, "{p:?}");
            assert!(p[2] > 0.02 && p[2] < 0.54, "{p:?}");
        }
        // Some were moved: the grid is not the plain one.
        let relocated = probes
            .iter()
            .filter(|p| {
                [0.1, 0.37, 0.63, 0.9].iter().all(|f| (p[0] - f * 0.556).abs() > 1e-9)
                    || [0.1, 0.37, 0.63, 0.9].iter().all(|f| (p[1] - f * 0.5488).abs() > 1e-9)
                    || [0.1, 0.37, 0.63, 0.9].iter().all(|f| (p[2] - f * 0.5592).abs() > 1e-9)
            })
            .count();
        assert!((3..=16).contains(&relocated), "{relocated}");
    }

    /// A ray from inside the box hits something in every direction but the open front; a
    /// closed-form check: straight up from under the light's centre, the light's radiance.
    #[test]
    fn rays_from_inside_meet_the_box_or_leave_through_the_front() {
        let scene = Scene::new(Setup::BASE, 1.0);
        let o = [0.278, 0.4, 0.2795];
        let mut rng = Rng::new(1);
        let up = scene.hit(o, [0.0, 1.0, 0.0], f64::INFINITY).expect("the light");
        assert!((up.0 - 0.1487).abs() < 1e-9 && up.1.emit == EMISSION, "{}", up.0);
        for _ in 0..2000 {
            let d = rng.uniform_sphere();
            let h = scene.hit(o, d, f64::INFINITY);
            // The front (z = 0) is open: a miss leaves through it.
            if h.is_none() {
                let t = -o[2] / d[2];
                let p = add(o, mul(d, t));
                assert!(d[2] < 0.0 && p[0] > -1e-9 && p[0] < 0.5561 && p[1] > -1e-9, "{d:?}");
                assert!(p[1] < 0.5489, "{d:?}");
            }
        }
    }

    /// Irradiance at a point of the floor that sees the whole light past the blocks, by the
    /// direct-light estimate, against the form factor of the light (a fine midpoint sum).
    #[test]
    fn direct_light_matches_a_numerical_form_factor() {
        let scene = Scene::new(Setup::BASE, 1.0);
        let x = [0.1, 0.0, 0.5];
        let mut rng = Rng::new(3);
        let m = 200_000;
        let mut acc = 0.0;
        for _ in 0..m {
            acc += scene.direct(x, [0.0, 1.0, 0.0], [1.0; 3], &mut rng)[0];
        }
        // E/π·ρ with ρ = 1: radiance = E·1/π; E = L·∫cos cos/r² dA.
        let est = acc / m as f64;
        let (h, mut form) = (0.5487, 0.0);
        let k = 400;
        for i in 0..k {
            for j in 0..k {
                let lx = 0.213 + 0.130 * (i as f64 + 0.5) / k as f64 - x[0];
                let lz = 0.227 + 0.105 * (j as f64 + 0.5) / k as f64 - x[2];
                let r2 = lx * lx + lz * lz + h * h;
                form += h * h / (r2 * r2) * (0.130 * 0.105) / (k * k) as f64;
            }
        }
        let expected = EMISSION[0] * form / std::f64::consts::PI;
        // Measured: the sampled estimate within 0.3 % (its Monte Carlo error ≈ 0.1 %).
        assert!((est / expected - 1.0).abs() < 0.01, "{est} vs {expected}");
    }
}
