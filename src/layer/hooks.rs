//! The rapier physics hooks that switch rapier's own contact response off for the pairs we model,
//! and the one handle-keyed table of the colliders registered with the layer.
//!
//! They matter only where apples carry ball colliders (a user's world, or a scene with a surface
//! left to rapier's own contact): rapier then pairs apple colliders with surface colliders, and
//! `filter_contact_pair` returning `None` for the pairs the layer models clears their manifolds
//! (rapier-notes.md): rapier computes no contact geometry and applies no impulse; the layer finds
//! these contacts itself and computes them at the current poses. Pairs with a surface whose model
//! is `rigid` get rapier's ordinary response (`Some(COMPUTE_RIGID_IMPULSES)`). Collider-less
//! apples never reach rapier's pair finding at all.

use rapier3d_f64::data::Coarena;
use rapier3d_f64::geometry::{ColliderHandle, SolverFlags};
use rapier3d_f64::pipeline::{PairFilterContext, PhysicsHooks};

/// What a registered collider is to the layer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// An apple (a ball) whose contacts the layer computes.
    Apple,
    /// A surface whose contacts with apples the layer computes (Hertz law).
    HertzSurface,
    /// A surface whose contacts with apples rapier solves itself (`"contact_model": "rigid"`).
    RigidSurface,
}

/// A registered collider: its role and its index among the layer's apples or surfaces.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Registered {
    pub role: Role,
    pub index: u32,
}

impl Default for Registered {
    /// Only fills the unused slots of the table (rapier's `Coarena` needs a value for them).
    fn default() -> Self {
        Self {
            role: Role::RigidSurface,
            index: u32::MAX,
        }
    }
}

/// Pass `layer.hooks()` to `PhysicsPipeline::step` (or `PhysicsWorld::step_with_events`).
///
/// Roles live in rapier's `Coarena`, a table indexed by the collider's arena index (rapier calls
/// the filter for every pair every step: a hash map cost 10 % of a step, measured). It is also the
/// layer's own lookup from a collider to its apple or surface.
#[derive(Debug, Clone, Default)]
pub struct ContactHooks {
    table: Coarena<Registered>,
}

impl ContactHooks {
    pub(crate) fn set(&mut self, h: ColliderHandle, role: Role, index: u32) {
        self.table.insert(h.0, Registered { role, index });
    }

    pub(crate) fn get(&self, h: ColliderHandle) -> Option<Registered> {
        self.table.get(h.0).copied()
    }

    /// The role of a collider, if registered.
    pub fn role(&self, h: ColliderHandle) -> Option<Role> {
        self.get(h).map(|r| r.role)
    }

    /// Whether rapier must leave this pair's response to the layer.
    pub fn layer_owns(&self, c1: ColliderHandle, c2: ColliderHandle) -> bool {
        matches!(
            (self.role(c1), self.role(c2)),
            (Some(Role::Apple), Some(Role::Apple))
                | (Some(Role::Apple), Some(Role::HertzSurface))
                | (Some(Role::HertzSurface), Some(Role::Apple))
        )
    }
}

impl PhysicsHooks for ContactHooks {
    fn filter_contact_pair(&self, context: &PairFilterContext) -> Option<SolverFlags> {
        if self.layer_owns(context.collider1, context.collider2) {
            None
        } else {
            Some(SolverFlags::COMPUTE_RIGID_IMPULSES)
        }
    }
}
