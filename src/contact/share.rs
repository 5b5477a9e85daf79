//! How the energy a contact dissipates is shared between its two bodies (docs/damage.md,
//! section 1).
//!
//! The contact law (eq. 12, or a viscoelastic dashpot) gives the energy the *contact* loses in an
//! impact: the area of its force-overlap loop. What bruises an apple is the part of that loss
//! that happens in the apple's own flesh. The rule, and why:
//!
//! 1. **Stored energy follows compliance.** In a Hertz contact both surfaces carry the same
//!    pressure, and each gives way in proportion to its compliance c = (1 - nu^2)/E: body i's
//!    share of the approach is delta_i / u = c_i / (c_1 + c_2) at every load (Johnson, *Contact
//!    Mechanics*, 1985, section 4.2; physics.md section 5 places the contact point by the same
//!    split). The elastic work each body stores, integral of P d(delta_i), is then the same share
//!    of the whole: s_i = c_i / (c_1 + c_2).
//! 2. **Each body loses its own fraction of what it stores.** Body i dissipates eta_i of its
//!    stored energy in a load-unload cycle (its loss factor: 1 - e_i^2, e_i its restitution when
//!    struck by a rigid body). The contact's loss is then sum s_i eta_i U, and body 1's part of it
//!    is w_1 = s_1 eta_1 / (s_1 eta_1 + s_2 eta_2). This is the split the literature file infers
//!    (bruise-models.md M9, \[INF\]); no source measures it directly (Chen & Yazdani 1991, the
//!    paper that would, was not retrieved).
//! 3. **Unknown loss factors are the contact's own.** A material that states no loss factor
//!    loses the share the pair's law loses as a whole, 1 - e^2 with e the pair's nominal
//!    restitution (sqrt(ke) for eq. 12, physics.md section 3). With neither stated, w_1 = s_1:
//!    an apple on steel (s = 1 - 3e-5) takes the whole loss, two equal apples half each, an apple
//!    on a foam twice as compliant a third.
//!
//! The shares are applied pose by pose as the contact's loss accumulates (`record::events`), so a
//! pad, whose share changes as it is squeezed thin ([`super::padding`]), is integrated exactly.

/// Body 1's share of the deformation of a contact, and of the elastic energy it stores:
/// c1 / (c1 + c2), the compliances c = (1 - nu^2)/E of the two bodies (1/Pa).
#[inline]
pub fn stored_share(c1: f64, c2: f64) -> f64 {
    c1 / (c1 + c2)
}

/// Body 1's share of a contact's loss: s eta1 / (s eta1 + (1 - s) eta2), with s its share of the
/// stored energy ([`stored_share`]) and eta1, eta2 the loss factors of the two bodies. When
/// neither body loses anything the loss is nil whatever the split: the stored share is returned.
#[inline]
pub fn loss_share(stored_share1: f64, eta1: f64, eta2: f64) -> f64 {
    let w1 = stored_share1 * eta1;
    let w = w1 + (1.0 - stored_share1) * eta2;
    if w > 0.0 {
        w1 / w
    } else {
        stored_share1
    }
}

/// The loss factor of a pair as a whole, 1 - e^2 with `restitution` e the pair's nominal
/// coefficient of restitution: what a body that states no loss factor of its own is taken to
/// lose of the energy it stores (rule 3 above).
#[inline]
pub fn pair_loss_factor(restitution: f64) -> f64 {
    (1.0 - restitution * restitution).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shares_of_the_three_closed_cases() {
        // Apple (G 1.1 MPa, nu 0.18) on steel (E 207 GPa, nu 0.28): c = 3.727e-7 and 4.45e-12.
        let c_apple = (1.0 - 0.18f64 * 0.18) / (2.0 * 1.1e6 * 1.18);
        let c_steel = (1.0 - 0.28f64 * 0.28) / 2.0736e11;
        let s = stored_share(c_apple, c_steel);
        assert!(s > 1.0 - 2e-5 && s < 1.0, "{s}");
        // Equal loss factors: the stored share.
        assert_eq!(loss_share(s, 0.91, 0.91), s);
        // Two equal apples: half each.
        assert_eq!(stored_share(c_apple, c_apple), 0.5);
        // A foam of E 0.5 MPa, nu 0.3: c = 1.82e-6, the apple's share 0.170.
        let c_foam = (1.0 - 0.09) / 0.5e6;
        let s = stored_share(c_apple, c_foam);
        assert!((s - c_apple / (c_apple + c_foam)).abs() < 1e-15);
        assert!((s - 0.16997).abs() < 1e-4, "{s}");
        // A foam that loses twice the apple's fraction halves the apple's odds.
        let w = loss_share(s, 0.4, 0.8);
        assert!((w - s / (s + 2.0 * (1.0 - s))).abs() < 1e-15);
        // An elastic partner (eta 0) leaves the whole loss to the apple.
        assert_eq!(loss_share(0.3, 0.5, 0.0), 1.0);
        // Nobody loses: the stored share.
        assert_eq!(loss_share(0.3, 0.0, 0.0), 0.3);
        assert!((pair_loss_factor(0.3) - 0.91).abs() < 1e-15);
        assert_eq!(pair_loss_factor(1.2), 0.0);
    }
}
