//! Multiple importance sampling weights (Veach 1997, section 9.2).
//!
//! `nf` samples from strategy f with density `pf`, `ng` from g with density
//! `pg`; the weight is for a sample drawn from f. Delta distributions are
//! handled by the caller through BSDF/light flags, never by infinite pdfs.

/// Balance heuristic, eq. 9.4: `nf pf / (nf pf + ng pg)`.
#[inline]
pub fn balance_heuristic(nf: u32, pf: f32, ng: u32, pg: f32) -> f32 {
    let f = nf as f32 * pf;
    let g = ng as f32 * pg;
    if f == 0.0 {
        return 0.0;
    }
    f / (f + g)
}

/// Power heuristic, eq. 9.12: `(nf pf)^beta / ((nf pf)^beta + (ng pg)^beta)`.
/// Written as `1 / (1 + (g/f)^beta)` so huge pdfs cannot overflow to inf/inf.
#[inline]
pub fn power_heuristic(nf: u32, pf: f32, ng: u32, pg: f32, beta: f32) -> f32 {
    let f = nf as f32 * pf;
    let g = ng as f32 * pg;
    if f == 0.0 {
        return 0.0;
    }
    if g == 0.0 {
        return 1.0;
    }
    let ratio = g / f;
    let r = if beta == 2.0 {
        ratio * ratio
    } else {
        ratio.powf(beta)
    };
    1.0 / (1.0 + r)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_sum_to_one() {
        for (pf, pg) in [(1.0, 1.0), (0.1, 10.0), (1e-30, 1e30), (3.0, 0.0)] {
            let b = balance_heuristic(1, pf, 1, pg) + balance_heuristic(1, pg, 1, pf);
            let p = power_heuristic(1, pf, 1, pg, 2.0) + power_heuristic(1, pg, 1, pf, 2.0);
            assert!((b - 1.0).abs() < 1e-6, "{pf} {pg}: {b}");
            assert!((p - 1.0).abs() < 1e-6, "{pf} {pg}: {p}");
        }
    }

    #[test]
    fn power_with_beta_one_is_balance() {
        let a = power_heuristic(2, 0.3, 1, 0.7, 1.0);
        let b = balance_heuristic(2, 0.3, 1, 0.7);
        assert!((a - b).abs() < 1e-6);
        assert!((power_heuristic(1, 1.0, 1, 1.0, 2.0) - 0.5).abs() < 1e-7);
        assert!((power_heuristic(1, 2.0, 1, 1.0, 2.0) - 0.8).abs() < 1e-6);
    }

    #[test]
    fn huge_pdfs_do_not_overflow() {
        let w = power_heuristic(1, 1e30, 1, 1e25, 2.0);
        assert!(w.is_finite() && w > 0.99);
    }
}
