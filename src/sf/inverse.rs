//! Inverse spherical Fibonacci mapping (in progress).
