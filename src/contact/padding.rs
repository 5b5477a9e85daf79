//! A pad of finite thickness bonded on a surface (docs/physics.md section 13).
//!
//! A sphere of radius R pressed a depth delta into an elastic layer of thickness h (Young's
//! modulus E, Poisson ratio nu) bonded to a rigid substrate pushes back with (Dimitriadis,
//! Horkay, Maresca, Kachar & Chadwick, "Determination of elastic moduli of thin layers of soft
//! material using the atomic force microscope", Biophys. J. 82 (2002) 2798-2810, the bonded
//! case):
//!
//! ```text
//! F = 4/3 E/(1 - nu^2) R^(1/2) delta^(3/2) f(chi),   chi = sqrt(R delta) / h
//! f = 1 - (2 a0/pi) chi + (4 a0^2/pi^2) chi^2 - (8/pi^3)(a0^3 + 4 pi^2 b0/15) chi^3
//!       + (16 a0/pi^4)(a0^3 + 3 pi^2 b0/5) chi^4
//! a0 = -(1.2876 - 1.4678 nu + 1.3442 nu^2)/(1 - nu),   b0 = (0.6387 - 1.0277 nu + 1.5164 nu^2)/(1 - nu)
//! ```
//!
//! Half-space Hertz while chi -> 0, stiffer as the layer is squeezed thin. The series holds for
//! chi up to about 1; applesim does not extrapolate it: once chi reaches [`CHI_LIMIT`] (or the
//! pad's share of the overlap reaches [`BOTTOM_COMPRESSION`] of its thickness) the pad has
//! *bottomed out* and, beyond that overlap u_b, the apple presses on the substrate through the
//! crushed layer: the pad carries the force it carried at u_b, and the Hertz contact of the apple
//! with the substrate's material at overlap u - u_b is added.
//!
//! A deformable apple on the pad: the overlap u is shared between the two bodies by their
//! compliances c = (1 - nu^2)/E (as the contact point is, section 5): the pad's part is
//! delta = s u, s = c_pad/(c_apple + c_pad), chi = sqrt(R* delta)/h, and the thin-layer factor
//! stiffens the pad's compliance: 1/E* = c_apple + c_pad / f(chi). For a rigid sphere
//! (c_apple = 0) this is the paper's law exactly.

use super::material::Material;

/// The series' stated range: chi = sqrt(R delta)/h up to about 1.
pub const CHI_LIMIT: f64 = 1.0;

/// The pad's share of the overlap, over its thickness, at which it bottoms out whatever chi
/// (a layer cannot be squeezed to nothing; foams densify before).
pub const BOTTOM_COMPRESSION: f64 = 0.9;

/// Dimitriadis et al.'s alpha0 and beta0 of a layer bonded to its substrate, for Poisson ratio
/// `nu` (their eqs. for the bonded case; docs/physics.md 13.1).
pub fn bonded_alpha_beta(nu: f64) -> (f64, f64) {
    let a0 = -(1.2876 - 1.4678 * nu + 1.3442 * nu * nu) / (1.0 - nu);
    let b0 = (0.6387 - 1.0277 * nu + 1.5164 * nu * nu) / (1.0 - nu);
    (a0, b0)
}

/// The four coefficients c1..c4 of f(chi) = 1 + c1 chi + c2 chi^2 + c3 chi^3 + c4 chi^4 for a
/// bonded layer of Poisson ratio `nu`.
pub fn series_coefficients(nu: f64) -> [f64; 4] {
    use std::f64::consts::PI;
    let (a, b) = bonded_alpha_beta(nu);
    let pi2 = PI * PI;
    [
        -2.0 * a / PI,
        4.0 * a * a / pi2,
        -8.0 / (pi2 * PI) * (a * a * a + 4.0 * pi2 * b / 15.0),
        16.0 * a / (pi2 * pi2) * (a * a * a + 3.0 * pi2 * b / 5.0),
    ]
}

/// f(chi) from the coefficients of [`series_coefficients`].
#[inline]
pub fn thin_layer_factor(c: &[f64; 4], chi: f64) -> f64 {
    1.0 + chi * (c[0] + chi * (c[1] + chi * (c[2] + chi * c[3])))
}

/// The overlap at which a pad of thickness `h` bottoms out under a contact of effective radius
/// `r_star`, the pad taking the share `pad_share` of the overlap: the smaller of the overlap at
/// which chi = sqrt(R* pad_share u)/h reaches [`CHI_LIMIT`] and the one at which the pad's share
/// reaches [`BOTTOM_COMPRESSION`] h.
pub fn bottom_overlap(h: f64, r_star: f64, pad_share: f64) -> f64 {
    let at_chi = CHI_LIMIT * CHI_LIMIT * h * h / (r_star * pad_share);
    let at_compression = BOTTOM_COMPRESSION * h / pad_share;
    at_chi.min(at_compression)
}

/// A limit of the thin-layer law an apple's contact has passed ([`PadConstants::limit_at`]).
///
/// chi reaches [`CHI_LIMIT`] when the pad is compressed by h / R* (chi^2 = R* delta / h^2 = 1):
/// 7.5 % for a 3 mm pad under an 80 mm apple on a flat (R* 40 mm), 25 % for a 10 mm one. That is
/// the end of the series' validity, not a crushed pad; the pad bottoms out when the half-space
/// split of the overlap would compress it by [`BOTTOM_COMPRESSION`] of its thickness.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum PadLimit {
    /// chi = sqrt(R* delta)/h reached [`CHI_LIMIT`]: beyond the law's validity; the model then
    /// adds the substrate's Hertz contact, an approximation of a stiffening pad.
    LawValidity,
    /// The pad is compressed to [`BOTTOM_COMPRESSION`] of its thickness: it has bottomed out, the
    /// apple presses on the substrate.
    Crushed,
}

/// The constants of an apple's contact with a padded surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PadConstants {
    /// f(chi)'s coefficients (the pad's Poisson ratio).
    pub coefficients: [f64; 4],
    /// sqrt(R* s_pad) / h, s_pad = c_pad / (c_apple + c_pad) the pad's share of the overlap:
    /// chi = sqrt(u) times this.
    pub chi_per_root_u: f64,
    /// The apple's compliance (1 - nu^2)/E (1/Pa).
    pub c_apple: f64,
    /// The pad's compliance (1 - nu^2)/E (1/Pa).
    pub c_pad: f64,
    /// 4/3 sqrt(R*): the Hertz stiffness over E*.
    pub four_thirds_root_r: f64,
    /// Hertz stiffness 4/3 E* sqrt(R*) of the apple on the substrate's material (N/m^(3/2)).
    pub substrate_stiffness: f64,
    /// Overlap at which the pad bottoms out (m), [`bottom_overlap`].
    pub bottom_overlap_m: f64,
    /// The substrate's compliance (1 - nu^2)/E (1/Pa).
    pub c_substrate: f64,
    /// Loss factors of the apple, the pad and the substrate ([`super::share`]).
    pub loss_factors: [f64; 3],
    /// Overlap at which chi reaches [`CHI_LIMIT`] (m).
    pub validity_overlap_m: f64,
    /// Overlap at which the pad's share reaches [`BOTTOM_COMPRESSION`] of its thickness (m).
    pub crushed_overlap_m: f64,
    /// The pad's compression (its share of the overlap over its thickness) at chi = 1.
    pub validity_compression: f64,
}

fn compliance(m: &Material) -> f64 {
    m.compliance()
}

impl PadConstants {
    /// The constants of an apple of material `apple` touching a pad of material `pad` and
    /// thickness `thickness_m` bonded on `substrate`, the contact's effective radius `r_star_m`.
    pub fn new(
        apple: &Material,
        pad: &Material,
        substrate: &Material,
        thickness_m: f64,
        r_star_m: f64,
        loss_factors: [f64; 3],
    ) -> Self {
        let (c_apple, c_pad) = (compliance(apple), compliance(pad));
        let four_thirds_root_r = 4.0 / 3.0 * r_star_m.sqrt();
        let share = c_pad / (c_apple + c_pad);
        Self {
            coefficients: series_coefficients(pad.poisson_ratio),
            chi_per_root_u: (r_star_m * share).sqrt() / thickness_m,
            c_apple,
            c_pad,
            four_thirds_root_r,
            substrate_stiffness: four_thirds_root_r / (c_apple + compliance(substrate)),
            bottom_overlap_m: bottom_overlap(thickness_m, r_star_m, share),
            c_substrate: compliance(substrate),
            loss_factors,
            validity_overlap_m: CHI_LIMIT * CHI_LIMIT * thickness_m * thickness_m
                / (r_star_m * share),
            crushed_overlap_m: BOTTOM_COMPRESSION * thickness_m / share,
            validity_compression: CHI_LIMIT * CHI_LIMIT * thickness_m / r_star_m,
        }
    }

    /// The furthest limit of the law the overlap `u` has passed, with the pad's compression at
    /// that limit: bottomed out once the pad's share of `u` reaches 90 % of its thickness, else
    /// beyond the law's validity once chi reached 1; `None` within the law.
    pub fn limit_at(&self, u: f64) -> Option<(PadLimit, f64)> {
        if u > self.crushed_overlap_m {
            Some((PadLimit::Crushed, BOTTOM_COMPRESSION))
        } else if u > self.validity_overlap_m {
            Some((PadLimit::LawValidity, self.validity_compression))
        } else {
            None
        }
    }

    /// The apple's share of the deformation and of the loss at overlap `u` ([`super::share`]):
    /// against the pad the pad's compliance stiffened by the thin-layer factor, c_pad / f(chi),
    /// the compliance that gives the pad law's force; once the pad has bottomed out, what more
    /// the contact takes goes into the apple and the substrate.
    #[inline]
    pub fn apple_shares(&self, u: f64) -> (f64, f64) {
        let [eta_apple, eta_pad, eta_sub] = self.loss_factors;
        let (c_other, eta_other) = if u > self.bottom_overlap_m {
            (self.c_substrate, eta_sub)
        } else {
            let chi = self.chi_per_root_u * u.max(0.0).sqrt();
            (
                self.c_pad / thin_layer_factor(&self.coefficients, chi),
                eta_pad,
            )
        };
        let s = super::share::stored_share(self.c_apple, c_other);
        (s, super::share::loss_share(s, eta_apple, eta_other))
    }

    /// The elastic normal force at overlap `u` (N), and whether the pad has bottomed out
    /// (u beyond [`Self::bottom_overlap_m`]).
    #[inline]
    pub fn elastic_force(&self, u: f64) -> (f64, bool) {
        let u = u.max(0.0);
        let ub = self.bottom_overlap_m;
        // Bottomed out: the crushed pad carries what it carried at u_b, the substrate the rest.
        let up = u.min(ub);
        let chi = self.chi_per_root_u * up.sqrt();
        let f = thin_layer_factor(&self.coefficients, chi);
        let e_star = 1.0 / (self.c_apple + self.c_pad / f);
        let pad = self.four_thirds_root_r * e_star * up * up.sqrt();
        if u > ub {
            let d = u - ub;
            (pad + self.substrate_stiffness * d * d.sqrt(), true)
        } else {
            (pad, false)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_law_ends_at_chi_one_before_the_pad_is_crushed() {
        let apple = Material::from_youngs(2.6e6, 0.18, Some(800.0)).unwrap();
        let foam = Material::from_youngs(2.0e6, 0.3, None).unwrap();
        let steel = Material::from_shear(8.1e10, 0.28, None).unwrap();
        let s = compliance(&foam) / (compliance(&apple) + compliance(&foam));
        // 3 mm and 10 mm pads under an 80 mm apple on a flat: h / R* = 7.5 % and 25 % at chi = 1.
        for (h, at_chi) in [(0.003, 0.075), (0.010, 0.25)] {
            let p = PadConstants::new(&apple, &foam, &steel, h, 0.04, [0.9; 3]);
            assert!((p.validity_compression - at_chi).abs() < 1e-15);
            let u_chi = at_chi * h / s;
            assert!((p.validity_overlap_m / u_chi - 1.0).abs() < 1e-12);
            assert_eq!(p.limit_at(0.99 * u_chi), None);
            assert_eq!(
                p.limit_at(1.01 * u_chi),
                Some((PadLimit::LawValidity, at_chi))
            );
            // Crushed once s u reaches 0.9 h.
            let u_crush = 0.9 * h / s;
            assert!((p.crushed_overlap_m / u_crush - 1.0).abs() < 1e-12);
            assert_eq!(p.limit_at(1.01 * u_crush), Some((PadLimit::Crushed, 0.9)));
            assert_eq!(
                p.bottom_overlap_m,
                p.validity_overlap_m.min(p.crushed_overlap_m)
            );
        }
    }

    #[test]
    fn incompressible_coefficients_are_the_papers_eq_12() {
        // At nu = 0.5 the paper prints 1 + 1.133 chi + 1.283 chi^2 + 0.769 chi^3 + 0.0975 chi^4;
        // its general form gives the same first three and -0.0975 (docs/physics.md 13.1).
        let c = series_coefficients(0.5);
        assert!((c[0] - 1.133).abs() < 5e-4, "{c:?}");
        assert!((c[1] - 1.283).abs() < 5e-4, "{c:?}");
        assert!((c[2] - 0.769).abs() < 5e-4, "{c:?}");
        assert!((c[3] + 0.0975).abs() < 5e-4, "{c:?}");
    }

    #[test]
    fn thick_pad_is_hertz_thin_pad_is_stiffer_and_bottoms_out() {
        let apple = Material::from_youngs(2.6e6, 0.18, Some(800.0)).unwrap();
        let foam = Material::from_youngs(1.0e6, 0.3, None).unwrap();
        let steel = Material::from_shear(8.1e10, 0.28, None).unwrap();
        let r: f64 = 0.037;
        let hertz =
            |u: f64| 4.0 / 3.0 / (compliance(&apple) + compliance(&foam)) * r.sqrt() * u.powf(1.5);
        let thick = PadConstants::new(&apple, &foam, &steel, 10.0, r, [0.9; 3]);
        let u = 1e-3;
        assert!((thick.elastic_force(u).0 / hertz(u) - 1.0).abs() < 1e-3);
        let thin = PadConstants::new(&apple, &foam, &steel, 0.012, r, [0.9; 3]);
        assert!(thin.elastic_force(u).0 > 1.05 * hertz(u));
        assert!(!thin.elastic_force(u).1);
        // h^2/(R* s) = 3.89 mm / s: bottomed beyond, and the substrate's Hertz added.
        let s = compliance(&foam) / (compliance(&apple) + compliance(&foam));
        assert!((thin.bottom_overlap_m / (0.012 * 0.012 / (r * s)) - 1.0).abs() < 1e-12);
        let (f, bottomed) = thin.elastic_force(6e-3);
        assert!(bottomed);
        let d: f64 = 6e-3 - thin.bottom_overlap_m;
        assert!(f > thin.substrate_stiffness * d.powf(1.5));
        // Continuous at the bottoming overlap.
        let ub = thin.bottom_overlap_m;
        let (below, above) = (
            thin.elastic_force(ub * (1.0 - 1e-12)).0,
            thin.elastic_force(ub * (1.0 + 1e-12)).0,
        );
        assert!((above / below - 1.0).abs() < 1e-9);
    }
}
