//! What the layer knows of the world it is attached to: materials and the contact law of each
//! pair of them, the apples (their bodies, radii, masses) and the surfaces (their colliders,
//! shapes, belts). Everything here is set at registration and read by every step; nothing here
//! changes while the world steps.

use super::bodies::BodyRef;
use super::config::{Coefficients, LayerConfig, SurfaceOptions};
use super::error::LayerError;
use super::hooks::{ContactHooks, Role};
use super::surface::SurfaceShape;
use crate::contact::spheroid::Spheroid;
use crate::contact::{self, Material, PairLaw};
use crate::math::Vec3;
use crate::record::events::{Names, Party};
use rapier3d_f64::data::Coarena;
use rapier3d_f64::dynamics::{RigidBodyAdditionalMassProps, RigidBodySet};
use rapier3d_f64::geometry::{ColliderHandle, ColliderSet, InteractionGroups};
use rapier3d_f64::pipeline::ActiveHooks;
use std::collections::HashMap;
use std::sync::Arc;

/// Index of a material registered with [`super::ContactLayer::add_material`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct MaterialId(pub u16);

/// Index of an apple in the layer (registration order).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct AppleId(pub u32);

/// Index of a surface in the layer (registration order).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SurfaceId(pub u32);

/// An apple as the layer knows it.
#[derive(Debug, Clone)]
pub(super) struct AppleEntry {
    pub name: Arc<str>,
    pub body: BodyRef,
    /// Centre of the ball in the body's frame.
    pub offset: Vec3,
    /// The ball is centred on the body's centre of mass: its centre is the body's translation
    /// when `offset` is zero, and its velocity the body's linear velocity.
    pub centred: bool,
    pub radius: f64,
    pub material: MaterialId,
    pub mass: f64,
    /// 1/m + r^2/I: inverse mass of the surface point in a tangential direction.
    pub inv_tangential_mass: f64,
    /// Moment of inertia about the centre (kg m^2); a spheroid's about an equatorial axis.
    pub inertia: f64,
    /// A spheroidal apple's shape (`radius` is then its bounding radius); `None`: a sphere.
    pub shape: Option<Spheroid>,
}

/// A surface as the layer knows it.
#[derive(Debug, Clone)]
pub(super) struct SurfaceEntry {
    pub name: Arc<str>,
    pub collider: ColliderHandle,
    pub material: MaterialId,
    pub shape: SurfaceShape,
    pub belt_local: Vec3,
    pub rigid: bool,
    /// A pad bonded on it (`material` is the substrate's).
    pub padding: Option<super::config::Padding>,
    /// Turned by its contacts: R^2 / I of its surface point (see `SurfaceOptions`).
    pub turned_by_contacts: Option<f64>,
}

/// Materials, pair laws, apples and surfaces, with the handle-keyed tables that find them.
#[derive(Debug)]
pub(super) struct Registry {
    materials: Vec<(String, Material)>,
    default_coeffs: Coefficients,
    pair_coeffs: HashMap<(MaterialId, MaterialId), Coefficients>,
    /// The law of every (apple material, other material), row-major (see [`Self::law_index`]).
    laws: Vec<PairLaw>,
    laws_dirty: bool,
    pub apples: Vec<AppleEntry>,
    pub surfaces: Vec<SurfaceEntry>,
    /// Registered colliders: role and index (also the hooks rapier calls).
    pub hooks: ContactHooks,
    /// Apple of each registered rigid body (rapier's wake-ups are reported by body).
    /// Per body set (see [`BodyRef`]).
    apple_of_body: Vec<Coarena<u32>>,
}

impl Registry {
    pub fn new() -> Self {
        Self {
            materials: Vec::new(),
            default_coeffs: Coefficients::paper(0.0, 1.0, 0.0),
            pair_coeffs: HashMap::new(),
            laws: Vec::new(),
            laws_dirty: true,
            apples: Vec::new(),
            surfaces: Vec::new(),
            hooks: ContactHooks::default(),
            apple_of_body: Vec::new(),
        }
    }

    pub fn add_material(&mut self, name: &str, material: Material) -> MaterialId {
        self.materials.push((name.to_string(), material));
        self.laws_dirty = true;
        MaterialId((self.materials.len() - 1) as u16)
    }

    pub fn material(&self, id: MaterialId) -> &Material {
        &self.materials[id.0 as usize].1
    }

    pub fn material_name(&self, id: MaterialId) -> &str {
        &self.materials[id.0 as usize].0
    }

    pub fn set_default_coefficients(&mut self, c: Coefficients) {
        self.default_coeffs = c;
        self.laws_dirty = true;
    }

    pub fn set_pair_coefficients(&mut self, a: MaterialId, b: MaterialId, c: Coefficients) {
        self.pair_coeffs.insert((a.min(b), a.max(b)), c);
        self.laws_dirty = true;
    }

    pub fn coefficients(&self, a: MaterialId, b: MaterialId) -> Coefficients {
        *self
            .pair_coeffs
            .get(&(a.min(b), a.max(b)))
            .unwrap_or(&self.default_coeffs)
    }

    /// Builds the law table after a material or coefficient changed.
    pub fn ensure_laws(&mut self) {
        if !self.laws_dirty {
            return;
        }
        let n = self.materials.len();
        self.laws.clear();
        for a in 0..n {
            for b in 0..n {
                let c = self.coefficients(MaterialId(a as u16), MaterialId(b as u16));
                self.laws.push(
                    PairLaw::new(
                        &self.materials[a].1,
                        &self.materials[b].1,
                        c.friction,
                        c.ke,
                        c.lambda_s_m,
                    )
                    .with_models(c.models),
                );
            }
        }
        self.laws_dirty = false;
    }

    /// Index in [`Self::laws`] of the law of an apple of material `a` touching material `b`.
    #[inline]
    pub fn law_index(&self, a: MaterialId, b: MaterialId) -> usize {
        a.0 as usize * self.materials.len() + b.0 as usize
    }

    /// The law table (valid after [`Self::ensure_laws`]).
    #[inline]
    pub fn laws(&self) -> &[PairLaw] {
        &self.laws
    }

    /// Registers a ball collider on a dynamic body as an apple (see
    /// [`super::ContactLayer::add_apple`]).
    pub fn add_apple(
        &mut self,
        colliders: &mut ColliderSet,
        collider: ColliderHandle,
        material: MaterialId,
        name: &str,
        config: &LayerConfig,
    ) -> Result<AppleId, LayerError> {
        if self.hooks.get(collider).is_some() {
            return Err(LayerError::Duplicate(name.to_string()));
        }
        let co = colliders
            .get_mut(collider)
            .ok_or(LayerError::UnknownCollider(collider))?;
        let radius = co
            .shape()
            .as_ball()
            .map(|b| b.radius)
            .ok_or_else(|| LayerError::NotABall(name.to_string()))?;
        let body = co
            .parent()
            .ok_or_else(|| LayerError::NotABall(name.to_string()))?;
        let offset = co
            .position_wrt_parent()
            .map(|p| p.translation)
            .unwrap_or(Vec3::ZERO);
        let mp = co.mass_properties();
        let (mass, inertia) = (mp.mass(), mp.principal_inertia().x);
        if !(mass > 0.0 && inertia > 0.0) {
            return Err(LayerError::NotABall(name.to_string()));
        }
        if !config.passive {
            let g = config.apple_group;
            let old = co.collision_groups();
            co.set_collision_groups(InteractionGroups::new(g, old.filter & !g, old.test_mode));
            co.set_active_hooks(co.active_hooks() | ActiveHooks::FILTER_CONTACT_PAIRS);
        }
        let id = self.push_apple(AppleEntry {
            name: name.into(),
            body: body.into(),
            offset,
            centred: false,
            radius,
            material,
            mass,
            inv_tangential_mass: 1.0 / mass + radius * radius / inertia,
            inertia,
            shape: None,
        });
        self.hooks.set(collider, Role::Apple, id.0);
        Ok(id)
    }

    /// Registers a dynamic rigid body without a collider as an apple (see
    /// [`super::ContactLayer::add_apple_body`]).
    pub fn add_apple_body(
        &mut self,
        bodies: &RigidBodySet,
        body: BodyRef,
        radius_m: f64,
        material: MaterialId,
        name: &str,
    ) -> Result<AppleId, LayerError> {
        if self.apple_of(body).is_some() {
            return Err(LayerError::Duplicate(name.to_string()));
        }
        let rb = bodies
            .get(body.handle)
            .ok_or_else(|| LayerError::NoMass(name.to_string()))?;
        let mprops = rb.mass_properties();
        let mut mp = mprops.local_mprops;
        if mp.mass() <= 0.0 {
            // Not computed by rapier yet (the body was just built): its additional properties.
            if let Some(RigidBodyAdditionalMassProps::MassProps(m)) =
                mprops.additional_local_mprops.as_deref()
            {
                mp = *m;
            }
        }
        let (mass, inertia) = (mp.mass(), mp.principal_inertia().x);
        if !(rb.is_dynamic() && mass > 0.0 && inertia > 0.0 && radius_m > 0.0) {
            return Err(LayerError::NoMass(name.to_string()));
        }
        Ok(self.push_apple(AppleEntry {
            name: name.into(),
            body,
            offset: mp.local_com,
            centred: true,
            radius: radius_m,
            material,
            mass,
            inv_tangential_mass: 1.0 / mass + radius_m * radius_m / inertia,
            inertia,
            shape: None,
        }))
    }

    /// Registers a dynamic rigid body without a collider as a spheroidal apple (see
    /// [`super::ContactLayer::add_spheroid_body`]). A sphere (a = c) is registered as
    /// [`Self::add_apple_body`] does.
    pub fn add_spheroid_body(
        &mut self,
        bodies: &RigidBodySet,
        body: BodyRef,
        shape: Spheroid,
        material: MaterialId,
        name: &str,
    ) -> Result<AppleId, LayerError> {
        if !(shape.a > 0.0 && shape.c > 0.0 && shape.a.is_finite() && shape.c.is_finite()) {
            return Err(LayerError::NoMass(name.to_string()));
        }
        let id = self.add_apple_body(bodies, body, shape.bounding_radius(), material, name)?;
        if !shape.is_sphere() {
            let e = &mut self.apples[id.0 as usize];
            // The inertia about an equatorial axis (the body's own x principal moment); the
            // surface point's tangential inverse mass with the largest lever.
            e.shape = Some(shape);
        }
        Ok(id)
    }

    fn push_apple(&mut self, entry: AppleEntry) -> AppleId {
        let id = self.apples.len() as u32;
        let set = entry.body.set as usize;
        if self.apple_of_body.len() <= set {
            self.apple_of_body.resize_with(set + 1, Coarena::new);
        }
        self.apple_of_body[set].insert(entry.body.handle.0, id);
        self.apples.push(entry);
        AppleId(id)
    }

    /// Registers a surface collider (see [`super::ContactLayer::add_surface`]).
    pub fn add_surface(
        &mut self,
        colliders: &mut ColliderSet,
        collider: ColliderHandle,
        options: SurfaceOptions,
        passive: bool,
    ) -> Result<SurfaceId, LayerError> {
        if self.hooks.get(collider).is_some() {
            return Err(LayerError::Duplicate(options.name));
        }
        let co = colliders
            .get_mut(collider)
            .ok_or(LayerError::UnknownCollider(collider))?;
        if !passive {
            co.set_active_hooks(co.active_hooks() | ActiveHooks::FILTER_CONTACT_PAIRS);
        }
        let role = if options.rigid || passive {
            Role::RigidSurface
        } else {
            Role::HertzSurface
        };
        let id = self.surfaces.len() as u32;
        self.surfaces.push(SurfaceEntry {
            name: options.name.into(),
            collider,
            material: options.material,
            shape: options.shape,
            belt_local: options.belt_velocity_local,
            rigid: options.rigid,
            padding: options.padding,
            turned_by_contacts: options.turned_by_contacts,
        });
        self.hooks.set(collider, role, id);
        Ok(SurfaceId(id))
    }

    /// The apple of a rigid body, if it is one.
    #[inline]
    pub fn apple_of(&self, r: BodyRef) -> Option<usize> {
        self.apple_of_body
            .get(r.set as usize)?
            .get(r.handle.0)
            .map(|&k| k as usize)
    }

    /// Name of a party of a contact.
    pub fn name_of(&self, p: Party) -> &Arc<str> {
        match p {
            Party::Apple(j) => &self.apples[j as usize].name,
            Party::Surface(s) => &self.surfaces[s as usize].name,
        }
    }

    /// Who a contact is about.
    pub fn names(&self, i: u32, other: Party) -> Names {
        Names {
            a: self.apples[i as usize].name.clone(),
            b: self.name_of(other).clone(),
            a_index: i,
            b_party: other,
        }
    }

    /// Checks that no apple can meet a concave surface tighter than itself (conforming contact).
    pub fn check_conformity(&self) -> Result<(), LayerError> {
        for s in &self.surfaces {
            if let SurfaceShape::Trough { radius_m, .. } = s.shape {
                for a in &self.apples {
                    if contact::normal::effective_radius(1.0 / a.radius, -1.0 / radius_m).is_none()
                    {
                        return Err(LayerError::Conforming {
                            apple: a.name.to_string(),
                            surface: s.name.to_string(),
                            apple_radius_m: a.radius,
                            surface_radius_m: radius_m,
                        });
                    }
                }
            }
        }
        Ok(())
    }
}
