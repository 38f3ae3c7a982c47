//! The error-budget model's coefficient type, shared by the fitted numbers ([`super::model`])
//! and the code that fits and uses them ([`super::budget`]).

/// Fitted coefficients of one filter: e = a·texel_term + b·edge_term + c.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coeffs {
    /// Filter name (`grid::filter_name`).
    pub filter: &'static str,
    /// Band pixels per texel-in-pixels, per boundary pixel.
    pub a: f64,
    /// Band pixels per boundary pixel at any resolution.
    pub b: f64,
    /// Constant (interior errors: acne, leaks).
    pub c: f64,
}
