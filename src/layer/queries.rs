//! What the layer can tell about its apples, surfaces and contacts: read-only queries of the
//! facade, apart from the registration and the stepping in `mod.rs`.

use super::{
    AppleId, ContactEvent, ContactLayer, Names, OpenContact, Party, SlipSample, StepStats,
    SurfaceId, SurfaceShape,
};
use crate::math::Vec3;
use std::borrow::Cow;

impl ContactLayer {
    /// Number of apples.
    pub fn apple_count(&self) -> usize {
        self.registry.apples.len()
    }

    /// Name of an apple.
    pub fn apple_name(&self, id: AppleId) -> &str {
        &self.registry.apples[id.0 as usize].name
    }

    /// Radius of an apple (m).
    pub fn apple_radius(&self, id: AppleId) -> f64 {
        self.registry.apples[id.0 as usize].radius
    }

    /// The shape of a spheroidal apple (`None`: a sphere of [`Self::apple_radius`]).
    pub fn apple_shape(&self, id: AppleId) -> Option<crate::contact::spheroid::Spheroid> {
        self.registry.apples[id.0 as usize].shape
    }

    /// Whether any apple is a spheroid.
    pub fn has_spheroids(&self) -> bool {
        self.registry.apples.iter().any(|a| a.shape.is_some())
    }

    /// Mass of an apple (kg).
    pub fn apple_mass(&self, id: AppleId) -> f64 {
        self.registry.apples[id.0 as usize].mass
    }

    /// Number of surfaces.
    pub fn surface_count(&self) -> usize {
        self.registry.surfaces.len()
    }

    /// The reaction forces on the surfaces turned by their contacts (free-turning rollers) from
    /// the last force pass, in a fixed order: (surface, force on the surface, point of
    /// application). With adaptive steps each force carries its contact's leapfrog kick, as the
    /// apples' loads do. Empty without such surfaces.
    pub fn surface_reactions(&self) -> &[(SurfaceId, Vec3, Vec3)] {
        &self.loads.surface_reactions
    }

    /// Name of a surface.
    pub fn surface_name(&self, id: SurfaceId) -> &str {
        &self.registry.surfaces[id.0 as usize].name
    }

    /// Name of a surface's material.
    pub fn surface_material_name(&self, id: SurfaceId) -> &str {
        let m = self.registry.surfaces[id.0 as usize].material;
        self.registry.material_name(m)
    }

    /// How a surface's geometry is computed.
    pub fn surface_shape(&self, id: SurfaceId) -> &SurfaceShape {
        &self.registry.surfaces[id.0 as usize].shape
    }

    /// Who a contact is about (the names of an event's parties).
    pub fn names(&self, i: u32, other: Party) -> Names {
        self.registry.names(i, other)
    }

    /// Figures of the last step.
    pub fn stats(&self) -> StepStats {
        self.out.stats
    }

    /// Contacts that ended so far, in the order they ended.
    pub fn finished_events(&self) -> &[ContactEvent] {
        &self.out.finished
    }

    /// Takes out the warnings of pads that reached the end of the thin-layer law since the last
    /// call, once per contact, saying which case happened (docs/physics.md section 13): the
    /// law's validity (chi = 1: "beyond the thin-layer law's validity"), or a pad compressed to
    /// 90 % of its thickness ("bottomed out": the apple presses on the substrate).
    pub fn take_pad_warnings(&mut self) -> Vec<String> {
        std::mem::take(&mut self.out.pad_bottoms)
            .into_iter()
            .map(|b| {
                let surface = &self.registry.surfaces[b.surface as usize];
                let (h, pad) = surface.padding.map_or((0.0, ""), |p| {
                    (p.thickness_m, self.registry.material_name(p.material))
                });
                let (limit, compression) = b.limit;
                let pct = crate::math::human(100.0 * compression, 2, 1);
                match limit {
                    crate::contact::padding::PadLimit::LawValidity => format!(
                        "pad of surface '{}' ({} mm of {pad}) under apple '{}' at t = {} s: compressed {pct} % of its thickness, beyond the thin-layer law's validity (chi = sqrt(R* delta)/h reached 1, docs/physics.md section 13); the pad is not crushed, but from there the model adds the Hertz contact of the substrate ({}) to the pad's force, an approximation of the stiffening pad: treat this contact's force as indicative",
                        surface.name,
                        crate::math::human(h * 1e3, 3, 1),
                        self.registry.apples[b.apple as usize].name,
                        crate::math::secs(b.time_s),
                        self.registry.material_name(surface.material),
                    ),
                    crate::contact::padding::PadLimit::Crushed => format!(
                        "pad of surface '{}' ({} mm of {pad}) bottomed out under apple '{}' at t = {} s: compressed to {pct} % of its thickness, the apple presses on the substrate ({}) and its force is the substrate's (docs/physics.md section 13)",
                        surface.name,
                        crate::math::human(h * 1e3, 3, 1),
                        self.registry.apples[b.apple as usize].name,
                        crate::math::secs(b.time_s),
                        self.registry.material_name(surface.material),
                    ),
                }
            })
            .collect()
    }

    /// Takes the finished events out of the layer.
    pub fn take_finished_events(&mut self) -> Vec<ContactEvent> {
        std::mem::take(&mut self.out.finished)
    }

    /// The contacts still open, as events with no end (sorted by apple, then other party).
    pub fn open_events(&self) -> Vec<ContactEvent> {
        self.open_events_where(|_| true)
    }

    /// The contacts still open whose impact is over, as events (their impact final; see
    /// [`Self::open_events`] for every open contact, an impact in progress reported as far as it
    /// went). In the order of [`Self::open_events`].
    pub fn open_events_after_impact(&self) -> Vec<ContactEvent> {
        self.open_events_where(|o| o.impact_over())
    }

    /// The open contacts whose record passes `keep`, as events, sorted by apple, then other
    /// party, then start.
    fn open_events_where(
        &self,
        keep: impl Fn(&crate::record::events::OpenContact) -> bool,
    ) -> Vec<ContactEvent> {
        let mut out: Vec<ContactEvent> = self
            .contacts
            .iter_records_now()
            .filter_map(|(c, o)| {
                let o = o.filter(|o| keep(o))?;
                let names = self.registry.names(c.i, c.other);
                Some(match o {
                    Cow::Borrowed(o) => o.snapshot(names),
                    // A rider's record, carried on a copy already.
                    Cow::Owned(o) => o.into_snapshot(names),
                })
            })
            .collect();
        out.sort_by(|x, y| {
            (x.a_index, x.b_party.order(), x.t_start_s.to_bits()).cmp(&(
                y.a_index,
                y.b_party.order(),
                y.t_start_s.to_bits(),
            ))
        });
        out
    }

    /// Work done so far by the normal forces of the contacts still open (J): the energy the
    /// contacts hold or have lost so far (see `OpenContact::work_so_far_j`). A rider's carries
    /// owed (`ContactStore::carry_later`) change none of what it reads.
    pub fn open_contact_work_j(&self) -> f64 {
        self.contacts
            .iter()
            .filter_map(|c| c.record.as_ref())
            .map(OpenContact::work_so_far_j)
            .sum()
    }

    /// Open contacts, sleepers' frozen ones included: (all, apple-apple).
    pub fn contact_counts(&self) -> (usize, usize) {
        self.contacts.iter().fold((0, 0), |(all, aa), c| {
            (
                all + 1,
                aa + usize::from(matches!(c.other, Party::Apple(_))),
            )
        })
    }

    /// The slip of every contact evaluated at the last force pass, in a fixed order (needs
    /// [`super::LayerConfig::record_slips`]). Contacts of sleeping apples are not evaluated.
    pub fn slips(&self) -> &[SlipSample] {
        &self.out.slips
    }

    /// Total contact force on an apple at the last step (N); for a sleeper, the force it carried
    /// when it fell asleep (its contacts are frozen).
    pub fn apple_contact_force(&self, id: AppleId) -> Vec3 {
        let k = id.0 as usize;
        if self.sleep.is_asleep(k) || self.sleep.ride(k).is_some() {
            return self.sleep.sleep_force(k);
        }
        self.loads.force.get(k).copied().unwrap_or(Vec3::ZERO)
    }

    /// Contact torque on an apple at the last step (N m); zero for a sleeper.
    pub fn apple_contact_torque(&self, id: AppleId) -> Vec3 {
        let k = id.0 as usize;
        if self.sleep.is_asleep(k) {
            return Vec3::ZERO;
        }
        self.loads.torque.get(k).copied().unwrap_or(Vec3::ZERO)
    }

    /// Centre, velocity and angular velocity of an apple as the last force pass saw them.
    pub fn apple_motion(&self, id: AppleId) -> (Vec3, Vec3, Vec3) {
        let k = id.0 as usize;
        (self.frame.pos[k], self.frame.vel[k], self.frame.angvel[k])
    }

    /// Whether an apple is asleep.
    pub fn is_asleep(&self, id: AppleId) -> bool {
        self.sleep.is_asleep(id.0 as usize)
    }

    /// Number of apples asleep now.
    pub fn sleeping_count(&self) -> usize {
        self.sleep.asleep_count()
    }

    /// Number of apples awake now (integrated, their contacts evaluated): neither asleep nor
    /// riding a belt.
    pub fn awake_count(&self) -> usize {
        self.registry.apples.len() - self.sleep.asleep_count() - self.sleep.riding_count()
    }

    /// Whether an apple rides a running belt (carried at its velocity, its contact frozen; see
    /// [`SleepConfig::carried`](super::SleepConfig::carried)).
    pub fn is_riding(&self, id: AppleId) -> bool {
        self.sleep.ride(id.0 as usize).is_some()
    }

    /// Number of apples riding a belt now.
    pub fn riding_count(&self) -> usize {
        self.sleep.riding_count()
    }

    /// A riding apple's centre and velocity at time `t_s` (rapier holds it asleep where it began
    /// to ride: read riders' poses here); `None` for an apple that does not ride.
    pub fn rider_motion(&self, id: AppleId, t_s: f64) -> Option<(Vec3, Vec3)> {
        self.sleep
            .ride(id.0 as usize)
            .map(|r| (r.centre_at(t_s), r.velocity))
    }
}
