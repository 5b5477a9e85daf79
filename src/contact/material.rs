//! Elastic materials (paper eq. 2) and their pair combinations.
//!
//! A material is given by its shear modulus G or its Young's modulus E, plus Poisson's ratio nu.
//! The paper writes its compliance constant as q = (lambda + 2G) / (4 pi G (lambda + G)), which
//! equals (1 - nu^2) / (pi E) (physics.md section 1); the Hertz law only ever needs
//! (1 - nu^2) / E, which this module calls the *compliance*.

use thiserror::Error;

/// A mistake in a material's numbers. The scenario layer adds the field path.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum MaterialError {
    /// E or G is zero, negative or not finite.
    #[error("{field} = {value}: a modulus must be a finite number > 0 Pa")]
    BadModulus {
        /// `youngs_modulus_pa` or `shear_modulus_pa`.
        field: &'static str,
        /// The value seen.
        value: f64,
    },
    /// nu outside the open interval (-1, 0.5) where an isotropic solid is stable.
    #[error(
        "poisson_ratio = {0}: must lie in (-1, 0.5) (0.5 is incompressible, outside Hertz theory)"
    )]
    BadPoisson(f64),
    /// Density zero, negative or not finite.
    #[error("density_kg_m3 = {0}: must be a finite number > 0")]
    BadDensity(f64),
    /// A loss factor outside [0, 1].
    #[error(
        "loss_factor = {0}: must lie in [0, 1] (the share of its stored energy a body dissipates)"
    )]
    BadLossFactor(f64),
}

/// An isotropic linear-elastic material.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Young's modulus E (Pa).
    pub youngs_modulus_pa: f64,
    /// Shear modulus G (Pa); E = 2 G (1 + nu).
    pub shear_modulus_pa: f64,
    /// Poisson's ratio nu.
    pub poisson_ratio: f64,
    /// Density (kg/m^3), needed only for bodies whose mass is derived from it.
    pub density_kg_m3: Option<f64>,
    /// Share of the elastic energy stored in this body that it dissipates in one impact (its
    /// loss factor, 1 - e^2 of this material struck by a rigid body), if known: it decides how
    /// a contact's loss is shared between the two bodies ([`super::share`]). `None`: the body
    /// loses what its contact loses as a whole.
    pub loss_factor: Option<f64>,
}

fn check_modulus(field: &'static str, value: f64) -> Result<(), MaterialError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(MaterialError::BadModulus { field, value })
    }
}

fn check_common(nu: f64, density: Option<f64>) -> Result<(), MaterialError> {
    if !(nu.is_finite() && nu > -1.0 && nu < 0.5) {
        return Err(MaterialError::BadPoisson(nu));
    }
    if let Some(rho) = density {
        if !(rho.is_finite() && rho > 0.0) {
            return Err(MaterialError::BadDensity(rho));
        }
    }
    Ok(())
}

impl Material {
    /// A material from its shear modulus (paper eq. 2: E = 2 G (1 + nu)).
    pub fn from_shear(g_pa: f64, nu: f64, density: Option<f64>) -> Result<Self, MaterialError> {
        check_modulus("shear_modulus_pa", g_pa)?;
        check_common(nu, density)?;
        Ok(Self {
            youngs_modulus_pa: 2.0 * g_pa * (1.0 + nu),
            shear_modulus_pa: g_pa,
            poisson_ratio: nu,
            density_kg_m3: density,
            loss_factor: None,
        })
    }

    /// A material from its Young's modulus (G = E / (2 (1 + nu))).
    pub fn from_youngs(e_pa: f64, nu: f64, density: Option<f64>) -> Result<Self, MaterialError> {
        check_modulus("youngs_modulus_pa", e_pa)?;
        check_common(nu, density)?;
        Ok(Self {
            youngs_modulus_pa: e_pa,
            shear_modulus_pa: e_pa / (2.0 * (1.0 + nu)),
            poisson_ratio: nu,
            density_kg_m3: density,
            loss_factor: None,
        })
    }

    /// The same material with its own loss factor ([`Self::loss_factor`]), in [0, 1].
    pub fn with_loss_factor(mut self, eta: f64) -> Result<Self, MaterialError> {
        if !(eta.is_finite() && (0.0..=1.0).contains(&eta)) {
            return Err(MaterialError::BadLossFactor(eta));
        }
        self.loss_factor = Some(eta);
        Ok(self)
    }

    /// Lame's first parameter, lambda = 2 nu G / (1 - 2 nu) (eq. 2).
    pub fn lame_lambda_pa(&self) -> f64 {
        2.0 * self.poisson_ratio * self.shear_modulus_pa / (1.0 - 2.0 * self.poisson_ratio)
    }

    /// The paper's q = (lambda + 2G) / (4 pi G (lambda + G)) (eq. 2), in 1/Pa.
    pub fn paper_q(&self) -> f64 {
        let g = self.shear_modulus_pa;
        let l = self.lame_lambda_pa();
        (l + 2.0 * g) / (4.0 * std::f64::consts::PI * g * (l + g))
    }

    /// Normal compliance (1 - nu^2) / E, in 1/Pa; equals pi q.
    pub fn compliance(&self) -> f64 {
        (1.0 - self.poisson_ratio * self.poisson_ratio) / self.youngs_modulus_pa
    }

    /// Tangential compliance (2 - nu) / G used by Mindlin's tangential stiffness.
    pub fn shear_compliance(&self) -> f64 {
        (2.0 - self.poisson_ratio) / self.shear_modulus_pa
    }
}

/// Effective modulus of a pair, 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2 (physics.md section 2).
///
/// The paper's eq. 4 has an extra factor 1/pi (erratum 1); this is classical Hertz and eq. 1.
pub fn effective_modulus(m1: &Material, m2: &Material) -> f64 {
    1.0 / (m1.compliance() + m2.compliance())
}

/// Effective shear modulus for Mindlin's tangential stiffness, 1/G* = (2-nu1)/G1 + (2-nu2)/G2.
pub fn effective_shear_modulus(m1: &Material, m2: &Material) -> f64 {
    1.0 / (m1.shear_compliance() + m2.shear_compliance())
}

/// Share of the overlap u taken up by body 1's surface: c1 / (c1 + c2) with c = (1 - nu^2)/E.
///
/// The contact plane sits where the two surfaces meet; each gives way in proportion to its
/// compliance (physics.md section 5), so a rigid flat leaves the whole overlap to the apple.
pub fn indentation_share(m1: &Material, m2: &Material) -> f64 {
    let c1 = m1.compliance();
    c1 / (c1 + m2.compliance())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eq2_conversions_agree() {
        let m = Material::from_shear(1.1e6, 0.18, Some(800.0)).unwrap();
        assert!((m.youngs_modulus_pa - 2.596e6).abs() < 1.0);
        let back = Material::from_youngs(m.youngs_modulus_pa, 0.18, None).unwrap();
        assert!((back.shear_modulus_pa - 1.1e6).abs() < 1e-6);
        // q from Lame constants equals (1 - nu^2)/(pi E): physics.md section 1.
        let q_closed = m.compliance() / std::f64::consts::PI;
        assert!((m.paper_q() - q_closed).abs() / q_closed < 1e-12);
    }

    #[test]
    fn fig1_effective_modulus_matches_rapier_notes() {
        // rapier-notes.md quotes E* = 2.6829e6 Pa for the Fig. 1 apple on steel.
        let apple = Material::from_shear(1.1e6, 0.18, Some(800.0)).unwrap();
        let steel = Material::from_shear(8.1e10, 0.28, None).unwrap();
        let e = effective_modulus(&apple, &steel);
        assert!((e - 2.6829e6).abs() / 2.6829e6 < 1e-4, "E* = {e}");
        assert!(indentation_share(&apple, &steel) > 0.9999);
        let share_equal = indentation_share(&apple, &apple);
        assert_eq!(share_equal, 0.5);
    }

    #[test]
    fn rejects_bad_numbers() {
        assert!(matches!(
            Material::from_shear(-1.0, 0.2, None),
            Err(MaterialError::BadModulus { .. })
        ));
        assert!(matches!(
            Material::from_youngs(f64::NAN, 0.2, None),
            Err(MaterialError::BadModulus { .. })
        ));
        assert_eq!(
            Material::from_shear(1e6, 0.5, None),
            Err(MaterialError::BadPoisson(0.5))
        );
        assert_eq!(
            Material::from_shear(1e6, -1.0, None),
            Err(MaterialError::BadPoisson(-1.0))
        );
        assert_eq!(
            Material::from_shear(1e6, 0.3, Some(0.0)),
            Err(MaterialError::BadDensity(0.0))
        );
    }
}
