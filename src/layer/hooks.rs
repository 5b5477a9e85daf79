//! The rapier physics hooks that switch rapier's own contact response off for the pairs we model.
//!
//! They matter only where apples carry ball colliders (a user's world, or a scene with a surface
//! left to rapier's own contact): rapier then pairs apple colliders with surface colliders, and
//! `filter_contact_pair` returning `None` for the pairs the layer models clears their manifolds
//! (rapier-notes.md): rapier computes no contact geometry and applies no impulse; the layer finds
//! these contacts itself and computes them at the current poses. Pairs with a surface whose model
//! is `rigid` get rapier's ordinary response (`Some(COMPUTE_RIGID_IMPULSES)`). Collider-less
//! apples never reach rapier's pair finding at all.

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

/// Pass `&layer.hooks()` to `PhysicsPipeline::step` (or `PhysicsWorld::step_with_events`).
///
/// Roles are kept in a plain table indexed by the collider's arena index (rapier calls the filter
/// for every pair every step: a hash map cost 10 % of a step, measured).
#[derive(Debug, Clone, Default)]
pub struct ContactHooks {
    roles: Vec<Option<(ColliderHandle, Role)>>,
}

impl ContactHooks {
    pub(crate) fn set(&mut self, h: ColliderHandle, role: Role) {
        let k = h.into_raw_parts().0 as usize;
        if self.roles.len() <= k {
            self.roles.resize(k + 1, None);
        }
        self.roles[k] = Some((h, role));
    }

    /// The role of a collider, if registered.
    pub fn role(&self, h: ColliderHandle) -> Option<Role> {
        match self.roles.get(h.into_raw_parts().0 as usize) {
            Some(Some((stored, role))) if *stored == h => Some(*role),
            _ => None,
        }
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
