//! 95 % intervals of a difference between two layouts (`applesim audit A B`, docs/damage.md
//! section 9): pure functions of the samples, each checked against a closed form in its tests.
//!
//! - [`newcombe`]: the difference of two proportions (the share of apples downgraded), by
//!   Newcombe's hybrid score interval (Newcombe 1998, Statistics in Medicine 17:873, method 10),
//!   built from each share's Wilson interval ([`wilson`]). Unlike the textbook Wald interval it
//!   keeps its coverage for small runs and shares near 0 or 1, and it is never a single point
//!   (0 of 20 against 0 of 20 gives about -16 to +16 percentage points).
//! - [`bootstrap`]: any figure of a run's apples (a total bruise volume, a 95th percentile), by
//!   the percentile bootstrap (Efron & Tibshirani 1993, ch. 13): each run's apples are drawn
//!   again with replacement, the figure recomputed on each draw; the 2.5 % and 97.5 % points of
//!   the differences bound the interval. Seeded (ChaCha8), so the same samples give the same
//!   bytes.
//! - [`paired_t`]: the mean of paired differences (one per feed seed), by Student's t.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The two-sided 97.5 % point of the standard normal distribution: a 95 % interval.
pub const Z_975: f64 = 1.959_963_984_540_054;

/// Resamples of [`bootstrap`] as `applesim audit` uses it.
pub const BOOTSTRAP_RESAMPLES: usize = 2000;

/// Seed of [`bootstrap`] as `applesim audit` uses it (any fixed number: the output must not
/// change from one call to the next).
pub const BOOTSTRAP_SEED: u64 = 26;

/// An estimate with its 95 % interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interval {
    /// The estimate (a difference A - B).
    pub estimate: f64,
    /// Lower bound.
    pub low: f64,
    /// Upper bound.
    pub high: f64,
}

impl Interval {
    /// Whether the interval holds `x` (bounds included).
    pub fn contains(&self, x: f64) -> bool {
        self.low <= x && x <= self.high
    }
}

/// The Wilson score interval of a proportion `k` of `n` (Wilson 1927), at `z`: centre
/// (p + z^2/2n) / (1 + z^2/n), half-width z sqrt(p(1-p)/n + z^2/4n^2) / (1 + z^2/n). `None`
/// when `n` is 0 or `k` > `n`.
pub fn wilson(k: usize, n: usize, z: f64) -> Option<(f64, f64)> {
    if n == 0 || k > n {
        return None;
    }
    let (kf, nf) = (k as f64, n as f64);
    let p = kf / nf;
    let z2 = z * z;
    let d = 1.0 + z2 / nf;
    let centre = (p + z2 / (2.0 * nf)) / d;
    let half = z / d * (p * (1.0 - p) / nf + z2 / (4.0 * nf * nf)).sqrt();
    // Exact at the ends (the formula gives them up to rounding).
    let low = if k == 0 { 0.0 } else { centre - half };
    let high = if k == n { 1.0 } else { centre + half };
    Some((low, high))
}

/// The 95 % interval of p1 - p2, p1 = `k1`/`n1` and p2 = `k2`/`n2` from independent samples, by
/// Newcombe's hybrid score method (method 10): with (l_i, u_i) the Wilson interval of p_i,
/// low = d - sqrt((p1 - l1)^2 + (u2 - p2)^2), high = d + sqrt((u1 - p1)^2 + (p2 - l2)^2),
/// d = p1 - p2. `None` when a sample is empty.
pub fn newcombe(k1: usize, n1: usize, k2: usize, n2: usize) -> Option<Interval> {
    let (l1, u1) = wilson(k1, n1, Z_975)?;
    let (l2, u2) = wilson(k2, n2, Z_975)?;
    let p1 = k1 as f64 / n1 as f64;
    let p2 = k2 as f64 / n2 as f64;
    let d = p1 - p2;
    Some(Interval {
        estimate: d,
        low: d - ((p1 - l1).powi(2) + (u2 - p2).powi(2)).sqrt(),
        high: d + ((u1 - p1).powi(2) + (p2 - l2).powi(2)).sqrt(),
    })
}

/// The value at quantile `q` of sorted `v` by nearest rank: the ceil(q n)-th smallest (as the
/// line audit's 95th percentiles are). NaN when `v` is empty.
pub fn nearest_rank(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let n = sorted.len();
    let k = ((q * n as f64).ceil() as usize).clamp(1, n);
    sorted[k - 1]
}

/// The percentile bootstrap interval of `stat(a) - stat(b)`, `a` and `b` independent samples
/// of units (apples), each resampled with replacement to its own size `resamples` times from a
/// ChaCha8 stream seeded with `seed`. A resample whose figure is not a number (a percentile of
/// no hits) is left out; `None` when either sample has fewer than 2 units, `stat` of either
/// whole sample is not a number, or fewer than 90 % of the resamples give a number. The bounds
/// are the 2.5 % and 97.5 % points of the resampled differences by nearest rank.
pub fn bootstrap<T>(
    a: &[T],
    b: &[T],
    stat: impl Fn(&[&T]) -> f64,
    resamples: usize,
    seed: u64,
) -> Option<Interval> {
    if a.len() < 2 || b.len() < 2 || resamples == 0 {
        return None;
    }
    let all = |s: &[T]| stat(&s.iter().collect::<Vec<_>>());
    let estimate = all(a) - all(b);
    if !estimate.is_finite() {
        return None;
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut draw = |s: &'_ [T]| -> f64 {
        let pick: Vec<&T> = (0..s.len())
            .map(|_| &s[rng.random_range(0..s.len())])
            .collect();
        stat(&pick)
    };
    let mut diffs: Vec<f64> = Vec::with_capacity(resamples);
    for _ in 0..resamples {
        let x = draw(a);
        let y = draw(b);
        let d = x - y;
        if d.is_finite() {
            diffs.push(d);
        }
    }
    if (diffs.len() as f64) < 0.9 * resamples as f64 {
        return None;
    }
    diffs.sort_by(f64::total_cmp);
    Some(Interval {
        estimate,
        low: nearest_rank(&diffs, 0.025),
        high: nearest_rank(&diffs, 0.975),
    })
}

/// The 95 % interval of the mean of paired differences `d` (one per feed seed) by Student's t:
/// mean +- t(0.975, n - 1) s / sqrt(n), s the sample standard deviation. `None` with fewer than
/// 2 differences or one that is not a number.
pub fn paired_t(d: &[f64]) -> Option<Interval> {
    let n = d.len();
    if n < 2 || d.iter().any(|x| !x.is_finite()) {
        return None;
    }
    let nf = n as f64;
    let mean = d.iter().sum::<f64>() / nf;
    let var = d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (nf - 1.0);
    let half = student_t_quantile(0.975, nf - 1.0) * (var / nf).sqrt();
    Some(Interval {
        estimate: mean,
        low: mean - half,
        high: mean + half,
    })
}

/// The sample mean and standard deviation of `v` (NaN standard deviation for fewer than 2).
pub fn mean_sd(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let sd = if v.len() < 2 {
        f64::NAN
    } else {
        (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
    };
    (mean, sd)
}

/// The quantile `p` (0 < p < 1) of Student's t distribution with `df` > 0 degrees of freedom:
/// the root of its distribution function, 1 - I_x(df/2, 1/2)/2 with x = df / (df + t^2) for
/// t > 0 ([`regularized_beta`]), found by bisection to 1e-12 (deterministic, no tables).
pub fn student_t_quantile(p: f64, df: f64) -> f64 {
    if !(p > 0.0 && p < 1.0 && df > 0.0) {
        return f64::NAN;
    }
    if p < 0.5 {
        return -student_t_quantile(1.0 - p, df);
    }
    if p == 0.5 {
        return 0.0;
    }
    // Upper tail probability of t: I_x(df/2, 1/2) / 2.
    let tail = |t: f64| 0.5 * regularized_beta(df / (df + t * t), 0.5 * df, 0.5);
    let target = 1.0 - p;
    let (mut lo, mut hi) = (0.0, 1.0);
    while tail(hi) > target {
        hi *= 2.0;
        if hi > 1e12 {
            return f64::INFINITY;
        }
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if tail(mid) > target {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-12 * hi {
            break;
        }
    }
    0.5 * (lo + hi)
}

/// The regularized incomplete beta function I_x(a, b), by its continued fraction (modified
/// Lentz; Press et al., Numerical Recipes, 3rd ed., section 6.4), using the symmetry
/// I_x(a, b) = 1 - I_{1-x}(b, a) where the fraction converges slowly.
pub fn regularized_beta(x: f64, a: f64, b: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    let ln_front =
        libm::lgamma(a + b) - libm::lgamma(a) - libm::lgamma(b) + a * x.ln() + b * (1.0 - x).ln();
    if x < (a + 1.0) / (a + b + 2.0) {
        ln_front.exp() * beta_fraction(x, a, b) / a
    } else {
        1.0 - ln_front.exp() * beta_fraction(1.0 - x, b, a) / b
    }
}

/// The continued fraction of the incomplete beta function.
fn beta_fraction(x: f64, a: f64, b: f64) -> f64 {
    const TINY: f64 = 1e-300;
    let (qab, qap, qam) = (a + b, a + 1.0, a - 1.0);
    let mut c = 1.0;
    let mut d = 1.0 - qab * x / qap;
    if d.abs() < TINY {
        d = TINY;
    }
    d = 1.0 / d;
    let mut h = d;
    for m in 1..=300 {
        let m = m as f64;
        let m2 = 2.0 * m;
        let aa = m * (b - m) * x / ((qam + m2) * (a + m2));
        d = 1.0 + aa * d;
        if d.abs() < TINY {
            d = TINY;
        }
        c = 1.0 + aa / c;
        if c.abs() < TINY {
            c = TINY;
        }
        d = 1.0 / d;
        h *= d * c;
        let aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
        d = 1.0 + aa * d;
        if d.abs() < TINY {
            d = TINY;
        }
        c = 1.0 + aa / c;
        if c.abs() < TINY {
            c = TINY;
        }
        d = 1.0 / d;
        let del = d * c;
        h *= del;
        if (del - 1.0).abs() < 1e-15 {
            break;
        }
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(x: f64, want: f64, tol: f64) {
        assert!(
            (x - want).abs() <= tol,
            "{x} against {want} (tolerance {tol})"
        );
    }

    #[test]
    fn t_quantile_meets_its_closed_forms_and_the_table() {
        // df = 1 (Cauchy): t = tan(pi (p - 1/2)).
        let p: f64 = 0.975;
        close(
            student_t_quantile(p, 1.0),
            (std::f64::consts::PI * (p - 0.5)).tan(),
            1e-9,
        );
        // df = 2: t = (2p - 1) / sqrt(2 p (1 - p)).
        close(
            student_t_quantile(p, 2.0),
            (2.0 * p - 1.0) / (2.0 * p * (1.0 - p)).sqrt(),
            1e-9,
        );
        // df = 4: t = sign(p-1/2) 2 sqrt(q - 1) with q = cos(acos(sqrt(alpha)) / 3) /
        // sqrt(alpha), alpha = 4 p (1 - p) (Hill 1970).
        let alpha = 4.0 * p * (1.0 - p);
        let q = ((alpha.sqrt()).acos() / 3.0).cos() / alpha.sqrt();
        close(student_t_quantile(p, 4.0), 2.0 * (q - 1.0).sqrt(), 1e-9);
        // The printed table (6 digits): df 3, 9, 29, and the normal limit.
        close(student_t_quantile(p, 3.0), 3.182446, 1e-6);
        close(student_t_quantile(p, 9.0), 2.262157, 1e-6);
        close(student_t_quantile(p, 29.0), 2.045230, 1e-6);
        close(student_t_quantile(p, 1e7), Z_975, 1e-6);
        close(student_t_quantile(0.025, 4.0), -2.776445, 1e-6);
        assert!(student_t_quantile(1.0, 3.0).is_nan());
    }

    #[test]
    fn wilson_and_newcombe_meet_the_published_examples() {
        // Newcombe 1998, Table II, method 10 (printed to 4 digits).
        let i = newcombe(56, 70, 48, 80).unwrap();
        close(i.estimate, 0.2, 1e-12);
        close(i.low, 0.0524, 5e-5);
        close(i.high, 0.3339, 5e-5);
        let i = newcombe(9, 10, 3, 10).unwrap();
        close(i.low, 0.1705, 5e-5);
        close(i.high, 0.8090, 5e-5);
        // Wilson 0 of 10: (0, z^2 / (n + z^2)).
        let (l, u) = wilson(0, 10, Z_975).unwrap();
        assert_eq!(l, 0.0);
        close(u, Z_975 * Z_975 / (10.0 + Z_975 * Z_975), 1e-15);
        // Equal shares: symmetric about 0, never a single point; 0 of n against 0 of n is
        // +- the Wilson upper bound z^2 / (n + z^2) (0.138 for 24 apples, docs/damage.md 9).
        let i = newcombe(0, 24, 0, 24).unwrap();
        close(i.low, -i.high, 1e-15);
        close(i.high, Z_975 * Z_975 / (24.0 + Z_975 * Z_975), 1e-15);
        assert!(i.contains(0.0));
        assert!(newcombe(1, 0, 0, 3).is_none());
    }

    #[test]
    fn paired_t_on_fixed_numbers() {
        // d = 1, 2, 3: mean 2, s 1, t(0.975, 2) = 4.302653 (closed form above).
        let i = paired_t(&[1.0, 2.0, 3.0]).unwrap();
        let t2 = 0.95 / (2.0f64 * 0.975 * 0.025).sqrt();
        close(i.estimate, 2.0, 1e-15);
        close(i.low, 2.0 - t2 / 3f64.sqrt(), 1e-9);
        close(i.high, 2.0 + t2 / 3f64.sqrt(), 1e-9);
        // Equal differences: a single point.
        let i = paired_t(&[0.0, 0.0, 0.0]).unwrap();
        assert_eq!((i.low, i.high), (0.0, 0.0));
        assert!(paired_t(&[1.0]).is_none());
        assert!(paired_t(&[1.0, f64::NAN]).is_none());
    }

    #[test]
    fn bootstrap_is_seeded_centred_and_closes_on_the_normal_interval() {
        let sum = |s: &[&f64]| s.iter().copied().sum::<f64>();
        // A sample against itself: the interval holds 0.
        let a: Vec<f64> = (0..40).map(|k| f64::from(k % 7) * 10.0).collect();
        let i = bootstrap(&a, &a, sum, 2000, 1).unwrap();
        assert_eq!(i.estimate, 0.0);
        assert!(i.contains(0.0), "{i:?}");
        assert_eq!(i, bootstrap(&a, &a, sum, 2000, 1).unwrap(), "seeded");
        // The total of n draws has standard error sqrt(n) sigma_n (sigma_n with divisor n);
        // two independent samples: sqrt(2 n) sigma_n; the percentile interval approaches
        // +- 1.96 of it. 20000 resamples: within 5 % of the half-width.
        let n = a.len() as f64;
        let m = a.iter().sum::<f64>() / n;
        let s = (a.iter().map(|x| (x - m).powi(2)).sum::<f64>() / n).sqrt();
        let half = Z_975 * (2.0 * n).sqrt() * s;
        let i = bootstrap(&a, &a, sum, 20000, 2).unwrap();
        close(0.5 * (i.high - i.low), half, 0.05 * half);
        // Constant samples: no scatter, the interval is the difference itself.
        let i = bootstrap(&[5.0, 5.0], &[2.0, 2.0, 2.0], sum, 100, 3).unwrap();
        assert_eq!((i.estimate, i.low, i.high), (4.0, 4.0, 4.0));
        assert!(bootstrap(&[1.0], &a, sum, 100, 3).is_none());
    }

    #[test]
    fn nearest_rank_as_the_audit() {
        let v: Vec<f64> = (1..=100).map(f64::from).collect();
        assert_eq!(nearest_rank(&v, 0.95), 95.0);
        assert_eq!(nearest_rank(&v, 0.025), 3.0);
        assert!(nearest_rank(&[], 0.5).is_nan());
    }
}
