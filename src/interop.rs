//! Conversions to and from [`mint`], the interoperability types of the Rust math crates
//! (feature `mint`).
//!
//! glam, nalgebra, cgmath and others convert their vectors and matrices to and from `mint`
//! types, so one pair of `From` impls here reaches all of them:
//!
//! | this crate | `mint` |
//! | --- | --- |
//! | [`Vec3`] | [`mint::Vector3<f32>`], [`mint::Point3<f32>`] |
//! | [`Mat3`] (stored as rows) | [`mint::RowMatrix3<f32>`], [`mint::ColumnMatrix3<f32>`] |
//!
//! Both matrix layouts convert to the same linear map: `Mat3 → ColumnMatrix3 → Mat3` and
//! `Mat3 → RowMatrix3 → Mat3` are the identity, and `M·v` is the same on both sides.
//!
//! With glam (its `mint` feature on):
//!
//! ```
//! use sphere_quadrature::{Mat3, Vec3};
//!
//! let normal = glam::Vec3::new(0.0, 0.6, 0.8);
//! let n: Vec3 = mint::Vector3::from(normal).into();
//! assert_eq!(n, Vec3::new(0.0, 0.6, 0.8));
//!
//! // A glam rotation (column-major) as this crate's rotation (rows), and back.
//! let q = glam::Quat::from_rotation_z(core::f32::consts::FRAC_PI_2);
//! let m: Mat3 = mint::ColumnMatrix3::from(glam::Mat3::from_quat(q)).into();
//! let x = m * Vec3::X;
//! assert!((x.y - 1.0).abs() < 1e-6 && x.x.abs() < 1e-6);
//! let back = glam::Mat3::from(mint::ColumnMatrix3::from(m));
//! assert!(back.abs_diff_eq(glam::Mat3::from_quat(q), 0.0));
//! ```

use crate::rotation::Mat3;
use crate::vec3::Vec3;

impl From<mint::Vector3<f32>> for Vec3 {
    #[inline]
    fn from(v: mint::Vector3<f32>) -> Self {
        Self::new(v.x, v.y, v.z)
    }
}

impl From<Vec3> for mint::Vector3<f32> {
    #[inline]
    fn from(v: Vec3) -> Self {
        Self { x: v.x, y: v.y, z: v.z }
    }
}

impl From<mint::Point3<f32>> for Vec3 {
    #[inline]
    fn from(p: mint::Point3<f32>) -> Self {
        Self::new(p.x, p.y, p.z)
    }
}

impl From<Vec3> for mint::Point3<f32> {
    #[inline]
    fn from(v: Vec3) -> Self {
        Self { x: v.x, y: v.y, z: v.z }
    }
}

impl From<mint::RowMatrix3<f32>> for Mat3 {
    #[inline]
    fn from(m: mint::RowMatrix3<f32>) -> Self {
        Self::from_rows(m.x.into(), m.y.into(), m.z.into())
    }
}

impl From<Mat3> for mint::RowMatrix3<f32> {
    #[inline]
    fn from(m: Mat3) -> Self {
        Self { x: m.rows[0].into(), y: m.rows[1].into(), z: m.rows[2].into() }
    }
}

impl From<mint::ColumnMatrix3<f32>> for Mat3 {
    #[inline]
    fn from(m: mint::ColumnMatrix3<f32>) -> Self {
        Self::from_rows(
            Vec3::new(m.x.x, m.y.x, m.z.x),
            Vec3::new(m.x.y, m.y.y, m.z.y),
            Vec3::new(m.x.z, m.y.z, m.z.z),
        )
    }
}

impl From<Mat3> for mint::ColumnMatrix3<f32> {
    #[inline]
    fn from(m: Mat3) -> Self {
        let [r0, r1, r2] = m.rows;
        Self {
            x: mint::Vector3 { x: r0.x, y: r1.x, z: r2.x },
            y: mint::Vector3 { x: r0.y, y: r1.y, z: r2.y },
            z: mint::Vector3 { x: r0.z, y: r1.z, z: r2.z },
        }
    }
}
