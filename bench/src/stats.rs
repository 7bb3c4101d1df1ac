//! Least-squares fits for the log-log plots.

/// Slope and intercept of the least-squares line through `(ln x, ln y)`, over the points with
/// `x > 0` and `y > 0`; `None` with fewer than two such points or all `x` equal.
#[must_use]
pub fn loglog_fit(points: &[(f64, f64)]) -> Option<(f64, f64)> {
    let logs: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0 && x.is_finite() && y.is_finite())
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    let n = logs.len() as f64;
    if logs.len() < 2 {
        return None;
    }
    let mx = logs.iter().map(|p| p.0).sum::<f64>() / n;
    let my = logs.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = logs.iter().map(|p| (p.0 - mx) * (p.0 - mx)).sum();
    let sxy: f64 = logs.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    if sxx <= 1e-300 {
        return None;
    }
    let slope = sxy / sxx;
    Some((slope, my - slope * mx))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_a_power_law() {
        let pts: Vec<(f64, f64)> = [1.0, 10.0, 100.0]
            .iter()
            .map(|&x| (x, 3.0 * x * x))
            .collect();
        let (slope, icpt) = loglog_fit(&pts).unwrap();
        assert!((slope - 2.0).abs() < 1e-12 && (icpt - 3f64.ln()).abs() < 1e-12);
        assert_eq!(loglog_fit(&[(1.0, 1.0)]), None);
        assert_eq!(loglog_fit(&[(2.0, 1.0), (2.0, 5.0)]), None);
        assert_eq!(loglog_fit(&[(1.0, 0.0), (2.0, 5.0)]), None);
    }
}
