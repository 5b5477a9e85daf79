//! How every CSV output prints a number ([`NumberFormat`]): one formatter, so that every file of a
//! run carries the same digits and the same run gives the same bytes.
//!
//! By default a number is rounded to 9 significant digits and printed in the shortest form that
//! reads back as that 9-digit value (`0.039959946189704366` -> `0.0399599462`, `0.5` -> `0.5`).
//! Why 9: a position of a few metres then resolves 10 nm, so an overlap of 0.1 mm rebuilt from two
//! printed positions keeps 4 digits (0.01 %), and every printed figure is ten thousand times finer
//! than the model's own accuracy (1 % on a peak force at 20 steps per contact, docs/accuracy.md);
//! it is also the precision that round-trips a 32-bit float, so a reader storing the columns as
//! `float32` loses nothing. `output.precision: "full"` prints Rust's shortest round-trip form of
//! the f64 (up to 17 digits).
//!
//! The form is positional (`0.0399599462`, `1250`, `0.00001`) from 1e-5 up to 1e15 and
//! scientific outside (`1.5e-7`, `2.5e21`), as C's `%g` chooses; pandas, R and Rust's
//! `f64::from_str` read both.

use std::fmt::Write as _;

/// Significant digits of a number in CSV outputs by default.
pub const DEFAULT_DIGITS: u8 = 9;

/// How numbers are printed: rounded to a number of significant digits, or in full.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NumberFormat {
    /// Significant digits (1 to 17); `None`: the shortest form that round-trips the f64.
    digits: Option<u8>,
}

impl Default for NumberFormat {
    fn default() -> Self {
        Self::digits(DEFAULT_DIGITS)
    }
}

impl NumberFormat {
    /// Full precision: every f64 reads back bit for bit.
    pub const FULL: NumberFormat = NumberFormat { digits: None };

    /// Rounded to `n` significant digits (clamped to 1..=17: 17 digits round-trip any f64).
    pub fn digits(n: u8) -> Self {
        Self {
            digits: Some(n.clamp(1, 17)),
        }
    }

    /// The significant digits, `None` in full precision.
    pub fn significant_digits(self) -> Option<u8> {
        self.digits
    }

    /// `x` as printed. NaN and infinities print as Rust prints them (`NaN`, `inf`, `-inf`).
    pub fn num(self, x: f64) -> String {
        let mut s = String::with_capacity(24);
        self.push(&mut s, x);
        s
    }

    /// `x` as printed, or an empty cell for `None`.
    pub fn opt(self, x: Option<f64>) -> String {
        x.map(|v| self.num(v)).unwrap_or_default()
    }

    /// A point as three numbers separated by spaces (the `contact_point_m` cells).
    pub fn point(self, p: [f64; 3]) -> String {
        let mut s = String::with_capacity(48);
        for (k, x) in p.iter().enumerate() {
            if k > 0 {
                s.push(' ');
            }
            self.push(&mut s, *x);
        }
        s
    }

    /// Appends `x` as printed to `out`.
    pub fn push(self, out: &mut String, x: f64) {
        if !x.is_finite() {
            out.push_str(&x.to_string());
            return;
        }
        if x == 0.0 {
            out.push_str(if x.is_sign_negative() { "-0" } else { "0" });
            return;
        }
        let mut buf = [b'0'; 24];
        let (neg, n, exp) = match self.digits.and_then(|d| rounded_fast(x, d, &mut buf)) {
            Some(found) => found,
            None => self.rounded_exact(x, &mut buf),
        };
        let mut n = n;
        while n > 1 && buf[n - 1] == b'0' {
            n -= 1;
        }
        let digits = std::str::from_utf8(&buf[..n.max(1)]).unwrap_or("0");
        if neg {
            out.push('-');
        }
        if (POSITIONAL_FROM..POSITIONAL_TO).contains(&exp) {
            push_positional(out, digits, exp);
        } else {
            out.push_str(&digits[..1]);
            if digits.len() > 1 {
                out.push('.');
                out.push_str(&digits[1..]);
            }
            out.push('e');
            out.push_str(&exp.to_string());
        }
    }
}

impl NumberFormat {
    /// The significant digits of `x` (rounded to the format's digits, or the shortest that
    /// round-trip) into `buf`: (negative, digit count, decimal exponent of the first digit).
    /// Rust's LowerExp gives the shortest round-trip digits without a precision, and correctly
    /// rounded ones with it; written into a buffer on the stack.
    fn rounded_exact(self, x: f64, buf: &mut [u8; 24]) -> (bool, usize, i32) {
        let mut sci = StackBuf::default();
        let _ = match self.digits {
            None => write!(sci, "{x:e}"),
            Some(n) => write!(sci, "{x:.*e}", usize::from(n - 1)),
        };
        let sci = sci.as_str();
        let (mantissa, exp) = sci.split_once('e').unwrap_or((sci, "0"));
        let exp: i32 = exp.parse().unwrap_or(0);
        let (neg, mantissa) = match mantissa.strip_prefix('-') {
            Some(m) => (true, m),
            None => (false, mantissa),
        };
        let mut n = 0;
        for c in mantissa.bytes().filter(|c| *c != b'.').take(buf.len()) {
            buf[n] = c;
            n += 1;
        }
        (neg, n.max(1), exp)
    }
}

/// Exact powers of ten as f64 (every one up to 1e22 is exactly representable).
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// `x` (finite, non-zero) rounded to `d` significant digits by one correctly rounded scaling
/// (x times or over an exact power of ten, relative error at most 2^-53) and a rounding to an
/// integer; the same digits as the exact conversion ([`NumberFormat::rounded_exact`]) whenever
/// the scaled value is not within 1e-6 of a rounding tie, and `None` (the exact conversion is
/// used) when it is, when the power of ten is not exact, or for more than 15 digits. Five times
/// faster than the exact conversion: `bodies.csv` prints fifteen numbers a row.
fn rounded_fast(x: f64, d: u8, buf: &mut [u8; 24]) -> Option<(bool, usize, i32)> {
    if d > 15 {
        return None;
    }
    let ax = x.abs();
    let mut exp = ax.log10().floor() as i32;
    for _ in 0..3 {
        let k = i32::from(d) - 1 - exp;
        let p = *POW10.get(k.unsigned_abs() as usize)?;
        let y = if k >= 0 { ax * p } else { ax / p };
        // log10 rounded across a power of ten: the first digit is one place off.
        if y >= POW10[usize::from(d)] {
            exp += 1;
            continue;
        }
        if y < POW10[usize::from(d) - 1] {
            exp -= 1;
            continue;
        }
        let frac = y - y.floor();
        if (frac - 0.5).abs() < 1e-6 {
            return None;
        }
        let mut q = y.round() as u64;
        if q as f64 >= POW10[usize::from(d)] {
            // Rounded up to the next power of ten (9.999999999 -> 10.0000000).
            q /= 10;
            exp += 1;
        }
        let mut n = usize::from(d);
        for i in (0..n).rev() {
            buf[i] = b'0' + (q % 10) as u8;
            q /= 10;
        }
        if q != 0 {
            return None;
        }
        while n > 1 && buf[n - 1] == b'0' {
            n -= 1;
        }
        return Some((x < 0.0, n, exp));
    }
    None
}

/// A small text buffer on the stack (a number in scientific form is at most 25 characters).
struct StackBuf {
    b: [u8; 40],
    n: usize,
}

impl Default for StackBuf {
    fn default() -> Self {
        Self { b: [0; 40], n: 0 }
    }
}

impl StackBuf {
    fn as_str(&self) -> &str {
        std::str::from_utf8(&self.b[..self.n]).unwrap_or("0")
    }
}

impl std::fmt::Write for StackBuf {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        let end = self.n + s.len();
        if end > self.b.len() {
            return Err(std::fmt::Error);
        }
        self.b[self.n..end].copy_from_slice(s.as_bytes());
        self.n = end;
        Ok(())
    }
}

/// Decimal exponents printed in positional form (`0.0000123`, `123456789000000`): from 1e-5 up to
/// (not including) 1e15, as C's `%g` does at these widths; smaller and larger numbers print in
/// scientific form (`1.5e-7`, `2.5e21`), shorter than their zeros.
const POSITIONAL_FROM: i32 = -5;
const POSITIONAL_TO: i32 = 15;

fn push_positional(out: &mut String, digits: &str, exp: i32) {
    let n = digits.len() as i32;
    if exp < 0 {
        out.push_str("0.");
        for _ in 0..(-exp - 1) {
            out.push('0');
        }
        out.push_str(digits);
    } else if exp + 1 >= n {
        out.push_str(digits);
        for _ in 0..(exp + 1 - n) {
            out.push('0');
        }
    } else {
        let (int, frac) = digits.split_at((exp + 1) as usize);
        out.push_str(int);
        out.push('.');
        out.push_str(frac);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Hand-written cases: rounding to 9 digits, the shortest form of the rounded value, the
    /// positional or scientific form whichever is shorter, signs, zeros and non-finite values.
    #[test]
    fn nine_digits_by_hand() {
        let f = NumberFormat::default();
        let cases: [(f64, &str); 25] = [
            (0.039959946189704366, "0.0399599462"),
            (0.1, "0.1"),
            (0.5, "0.5"),
            (1.0, "1"),
            (-1.0, "-1"),
            (0.0, "0"),
            (-0.0, "-0"),
            (123456789.0, "123456789"),
            (1234567891.0, "1234567890"),
            (1234567896.0, "1234567900"),
            (12345678912345.0, "12345678900000"),
            (1.2345678912345e15, "1.23456789e15"),
            (1e21, "1e21"),
            (2.5e21, "2.5e21"),
            (1500.0, "1500"),
            (0.30000000000000004, "0.3"),
            (1.0 / 3.0, "0.333333333"),
            (2.0 / 3.0, "0.666666667"),
            (-9.81, "-9.81"),
            (0.0001, "0.0001"),
            (0.00001, "0.00001"),
            (1.5e-7, "1.5e-7"),
            (1.23456789123e-7, "1.23456789e-7"),
            (9.999999999, "10"),
            (-0.00099999999951, "-0.001"),
        ];
        for (x, want) in cases {
            assert_eq!(f.num(x), want, "{x:e}");
        }
        assert_eq!(f.num(f64::NAN), "NaN");
        assert_eq!(f.num(f64::INFINITY), "inf");
        assert_eq!(f.num(f64::NEG_INFINITY), "-inf");
        assert_eq!(f.opt(None), "");
        assert_eq!(f.point([0.1, -2.0, 1e-9]), "0.1 -2 1e-9");
    }

    /// Printed values read back as the 9-digit value, and full precision reads back bit for bit.
    #[test]
    fn printed_values_read_back() {
        let mut x = 0.123456789012345_f64;
        for k in 0..2000 {
            x = (x * 7.3 + 0.31).fract() * 10f64.powi(k % 40 - 20);
            let s = NumberFormat::default().num(x);
            let nine: f64 = format!("{x:.8e}").parse().unwrap();
            assert_eq!(s.parse::<f64>().unwrap(), nine, "{x:e} -> {s}");
            let full = NumberFormat::FULL.num(x);
            assert_eq!(
                full.parse::<f64>().unwrap().to_bits(),
                x.to_bits(),
                "{full}"
            );
        }
        assert_eq!(
            NumberFormat::FULL.num(0.039959946189704366),
            "0.039959946189704366"
        );
        assert_eq!(NumberFormat::digits(3).num(9.81), "9.81");
        assert_eq!(NumberFormat::digits(2).num(9.81), "9.8");
        assert_eq!(NumberFormat::digits(0).num(9.81), "10");
    }
}
