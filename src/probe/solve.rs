//! Solves with the baked Cholesky factors (packed f32 bits), in f32 and f64.

use super::*;

/// `x ← (LLᵀ)⁻¹x` for `L` stored (as f32 bits) as packed lower-triangle rows with a reciprocal
/// diagonal:
/// forward substitution by rows, then back substitution by columns through the same rows.
pub(super) fn cholesky_solve<T: Radiance>(packed: &[u32], x: &mut [T]) {
    forward_solve(packed, x);
    back_solve(packed, x);
}

/// `x ← L⁻¹x` (forward substitution by rows) for the packed factor of [`cholesky_solve`].
pub(super) fn forward_solve<T: Radiance>(packed: &[u32], x: &mut [T]) {
    let mut rest = packed;
    for i in 0..x.len() {
        let Some((row, r)) = rest.split_at_checked(i + 1) else { return };
        rest = r;
        let Some((&inv, off)) = row.split_last() else { return };
        let (head, tail) = x.split_at_mut(i);
        let Some(xi) = tail.first_mut() else { return };
        let acc = off
            .iter()
            .zip(head.iter())
            .fold(*xi, |acc, (&l, &xj)| acc.mul_add(xj, -f32::from_bits(l)));
        *xi = acc.scale(f32::from_bits(inv));
    }
}

/// `x ← L⁻ᵀx` (back substitution by columns through the rows) for the packed factor of
/// [`cholesky_solve`].
pub(super) fn back_solve<T: Radiance>(packed: &[u32], x: &mut [T]) {
    let mut end = packed.len();
    for i in (0..x.len()).rev() {
        let start = end.saturating_sub(i + 1);
        let Some(row) = packed.get(start..end) else { return };
        end = start;
        let Some((&inv, off)) = row.split_last() else { return };
        let (head, tail) = x.split_at_mut(i);
        let Some(xi) = tail.first_mut() else { return };
        *xi = xi.scale(f32::from_bits(inv));
        let v = *xi;
        for (&l, xj) in off.iter().zip(head.iter_mut()) {
            *xj = xj.mul_add(v, -f32::from_bits(l));
        }
    }
}

/// `x ← L⁻¹x` (forward substitution only), in f64, for the packed factor as above.
pub(super) fn forward_substitution(packed: &[u32], x: &mut [f64]) {
    let mut rest = packed;
    for i in 0..x.len() {
        let Some((row, r)) = rest.split_at_checked(i + 1) else { return };
        rest = r;
        let Some((&inv, off)) = row.split_last() else { return };
        let (head, tail) = x.split_at_mut(i);
        let Some(xi) = tail.first_mut() else { return };
        let acc: f64 =
            off.iter().zip(head.iter()).map(|(&l, &xj)| f64::from(f32::from_bits(l)) * xj).sum();
        *xi = (*xi - acc) * f64::from(f32::from_bits(inv));
    }
}

/// `x ← L⁻ᵀx` (back substitution), in f64, for the packed factor as above.
pub(super) fn back_substitution(packed: &[u32], x: &mut [f64]) {
    let mut end = packed.len();
    for i in (0..x.len()).rev() {
        let start = end.saturating_sub(i + 1);
        let Some(row) = packed.get(start..end) else { return };
        end = start;
        let Some((&inv, off)) = row.split_last() else { return };
        let (head, tail) = x.split_at_mut(i);
        let Some(xi) = tail.first_mut() else { return };
        *xi *= f64::from(f32::from_bits(inv));
        let v = *xi;
        for (&l, xj) in off.iter().zip(head.iter_mut()) {
            *xj -= f64::from(f32::from_bits(l)) * v;
        }
    }
}
