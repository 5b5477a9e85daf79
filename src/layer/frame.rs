//! The per-step frame of the apples: where each awake apple is and how it moves at the current
//! poses (read from rapier once per step), how many contacts it has, and the loads the force pass
//! sums for it, handed to rapier at the end of the pass.

use super::bodies::BodySets;
use super::config::StepControl;
use super::error::LayerError;
use super::registry::AppleEntry;
use super::SurfaceId;
use crate::math::{is_finite, Vec3};
use rapier3d_f64::dynamics::RigidBodyHandle;
use rapier3d_f64::math::Rotation;

/// Poses and motion of the apples at the current poses (awake apples only: a sleeper keeps what
/// it had when it fell asleep, its velocities zeroed).
#[derive(Debug, Default)]
pub(super) struct Frame {
    pub pos: Vec<Vec3>,
    pub vel: Vec<Vec3>,
    pub angvel: Vec<Vec3>,
    /// Orientation (where a hit lands on the apple's own surface: bruise sites).
    pub rot: Vec<Rotation>,
    pub radius: Vec<f64>,
    /// Contacts seen this step.
    pub count: Vec<u16>,
    /// |v| and |w| R below the sleep threshold.
    pub still: Vec<bool>,
    /// A running belt (a surface on a fixed body with a belt velocity) the apple touches this
    /// step, with the belt's velocity (with one contact: it may ride it, see [`super::sleep`]).
    pub carrier: Vec<Option<(u32, Vec3)>>,
}

impl Frame {
    /// Sizes the arrays for `n` apples at the start of a step.
    pub fn begin(&mut self, n: usize) {
        self.pos.resize(n, Vec3::ZERO);
        self.vel.resize(n, Vec3::ZERO);
        self.angvel.resize(n, Vec3::ZERO);
        self.rot.resize(n, Rotation::IDENTITY);
        self.count.clear();
        self.count.resize(n, 0);
        self.still.resize(n, false);
        self.carrier.clear();
        self.carrier.resize(n, None);
    }

    /// Reads the awake apples' current state from rapier; non-finite state is refused here,
    /// before it can spread. With many awake apples and more than one thread, the bodies are
    /// read in parallel chunks of the awake list (a body read is a cache miss each), each
    /// writing its own range of the arrays: the same frame, and the same first error (the first
    /// in awake order), for any thread count.
    #[allow(clippy::too_many_arguments)]
    pub fn read(
        &mut self,
        bodies: &BodySets,
        apples: &[AppleEntry],
        awake: &[u32],
        riders: usize,
        riding: impl Fn(usize) -> bool + Sync,
        still_speed_m_s: f64,
        time_s: f64,
    ) -> Result<(), LayerError> {
        let mut all = Part {
            first: 0,
            pos: &mut self.pos,
            vel: &mut self.vel,
            angvel: &mut self.angvel,
            rot: &mut self.rot,
            still: &mut self.still,
        };
        // Riders are not read (the layer carries them): they are no work for the pool.
        if awake.len() - riders.min(awake.len()) >= PARALLEL_MIN_READS
            && rayon::current_num_threads() > 1
        {
            use rayon::prelude::*;
            // The awake list is increasing: its chunks name disjoint ranges of apples, and each
            // chunk writes its own range of the arrays.
            debug_assert!(awake.windows(2).all(|w| w[0] < w[1]));
            let mut rest = all;
            let mut parts = Vec::new();
            for chunk in awake.chunks(READ_CHUNK) {
                let end = *chunk.last().expect("chunks are not empty") as usize + 1;
                let (mine, tail) = rest.split(end);
                parts.push((chunk, mine));
                rest = tail;
            }
            let first_error = parts
                .into_par_iter()
                .map(|(chunk, mut part)| {
                    for &k in chunk {
                        if !riding(k as usize) {
                            let p =
                                read_pose(bodies, &apples[k as usize], still_speed_m_s, time_s)?;
                            part.put(k as usize, p);
                        }
                    }
                    Ok(())
                })
                .collect::<Vec<Result<(), LayerError>>>()
                .into_iter()
                .find_map(Result::err);
            if let Some(e) = first_error {
                return Err(e);
            }
        } else {
            for &k in awake {
                let k = k as usize;
                if riding(k) {
                    // The layer carries it (`Sleep::place_riders`); rapier holds it asleep.
                    continue;
                }
                let p = read_pose(bodies, &apples[k], still_speed_m_s, time_s)?;
                all.put(k, p);
            }
        }
        Ok(())
    }
}

/// Awake apples from which [`Frame::read`] reads the bodies in parallel (below, the pool's
/// overhead outweighs ~40 ns per body).
const PARALLEL_MIN_READS: usize = 256;

/// The arrays of a range of apples from `first` on (a chunk of [`Frame::read`]).
struct Part<'a> {
    first: usize,
    pos: &'a mut [Vec3],
    vel: &'a mut [Vec3],
    angvel: &'a mut [Vec3],
    rot: &'a mut [Rotation],
    still: &'a mut [bool],
}

impl<'a> Part<'a> {
    /// The apples before `end`, and those from it.
    fn split(self, end: usize) -> (Part<'a>, Part<'a>) {
        let at = end - self.first;
        let (pos, pos2) = self.pos.split_at_mut(at);
        let (vel, vel2) = self.vel.split_at_mut(at);
        let (angvel, angvel2) = self.angvel.split_at_mut(at);
        let (rot, rot2) = self.rot.split_at_mut(at);
        let (still, still2) = self.still.split_at_mut(at);
        (
            Part {
                first: self.first,
                pos,
                vel,
                angvel,
                rot,
                still,
            },
            Part {
                first: end,
                pos: pos2,
                vel: vel2,
                angvel: angvel2,
                rot: rot2,
                still: still2,
            },
        )
    }

    #[inline(always)]
    fn put(&mut self, k: usize, p: Pose) {
        let j = k - self.first;
        self.pos[j] = p.centre;
        self.vel[j] = p.vel;
        self.angvel[j] = p.angvel;
        self.rot[j] = p.rot;
        self.still[j] = p.still;
    }
}

/// Apples per parallel chunk of [`Frame::read`].
const READ_CHUNK: usize = 128;

/// One apple's state as read from its body.
#[derive(Debug, Clone, Copy)]
struct Pose {
    centre: Vec3,
    vel: Vec3,
    angvel: Vec3,
    rot: Rotation,
    still: bool,
}

/// Reads apple `a`'s ball centre, its velocity and spin from its body; refuses non-finite state.
#[inline(always)]
fn read_pose(
    bodies: &BodySets,
    a: &AppleEntry,
    still_speed_m_s: f64,
    time_s: f64,
) -> Result<Pose, LayerError> {
    let Some(rb) = bodies.get(a.body) else {
        return Err(LayerError::MissingBody {
            apple: a.name.to_string(),
            time_s,
        });
    };
    let pose = rb.position();
    let c = if a.offset == Vec3::ZERO {
        pose.translation
    } else {
        pose.transform_point(a.offset)
    };
    let w = rb.angvel();
    let v = if a.centred {
        rb.linvel()
    } else {
        rb.linvel() + w.cross(c - rb.center_of_mass())
    };
    if !(is_finite(c) && is_finite(v) && is_finite(w)) {
        return Err(LayerError::NonFinite {
            body: a.name.to_string(),
            time_s,
        });
    }
    let still2 = still_speed_m_s * still_speed_m_s;
    Ok(Pose {
        centre: c,
        vel: v,
        angvel: w,
        rot: pose.rotation,
        still: v.length_squared() < still2 && w.length_squared() * a.radius * a.radius < still2,
    })
}

/// The loads the force pass sums per apple, and what is handed to rapier.
#[derive(Debug, Default)]
pub(super) struct Loads {
    /// Total contact force and torque per apple (N, N m).
    pub force: Vec<Vec3>,
    pub torque: Vec<Vec3>,
    /// Adaptive steps only: contact force and torque with each contact's leapfrog kick (see
    /// [`StepControl`]): what is handed to rapier.
    pub kicked_force: Vec<Vec3>,
    pub kicked_torque: Vec<Vec3>,
    /// Touches an apple that is not still, or a moving surface: may not fall asleep.
    pub busy: Vec<bool>,
    /// The layer left a non-zero force or torque on the body at the last step (so a zero one now
    /// must be written: rapier keeps user forces).
    pub loaded: Vec<bool>,
    /// The forces handed to rapier this step, per body set: (body, force, torque).
    handoff: Vec<Vec<(RigidBodyHandle, Vec3, Vec3)>>,
    /// Reaction forces on dynamic surface bodies: (body, force, point).
    pub body_loads: Vec<(RigidBodyHandle, Vec3, Vec3)>,
    /// Reaction forces on the surfaces turned by their contacts, this step, in slot order:
    /// (surface, force on it with its kick, point).
    pub surface_reactions: Vec<(SurfaceId, Vec3, Vec3)>,
}

impl Loads {
    /// Clears the sums for `n` apples at the start of a step.
    pub fn begin(&mut self, n: usize, kicked: bool) {
        self.force.clear();
        self.force.resize(n, Vec3::ZERO);
        self.torque.clear();
        self.torque.resize(n, Vec3::ZERO);
        if kicked {
            self.kicked_force.clear();
            self.kicked_force.resize(n, Vec3::ZERO);
            self.kicked_torque.clear();
            self.kicked_torque.resize(n, Vec3::ZERO);
        }
        self.busy.clear();
        self.busy.resize(n, false);
        self.surface_reactions.clear();
        self.loaded.resize(n, false);
    }

    /// Hands the forces to rapier. `user_force` persists across steps, so whatever the layer left
    /// on a body is replaced; a body that had no load and gets none is not touched (rapier then
    /// has no change of it to process). With variable steps each contact carries its own kick
    /// (see `kernel`) and `kick` is gravity's share: (h_back + h) / (2 h), or 0.5 for an apple's
    /// first step (`first_step`), which starts the leapfrog from its initial velocity (measured:
    /// without it, a 6 mm drop on a belt in adaptive steps landed 4.6 % slow).
    #[allow(clippy::too_many_arguments)]
    pub fn hand_to_rapier(
        &mut self,
        bodies: &mut BodySets,
        apples: &[AppleEntry],
        awake: &[u32],
        idle: impl Fn(usize) -> bool,
        control: Option<StepControl>,
        kick: f64,
        gravity: Vec3,
        first_step: &mut [bool],
    ) {
        // With apple sets, each set's bodies are written by one task (rapier tracks the changes
        // per set), on the pool when there are many loads; else straight away, in awake order.
        let sets = !bodies.apple_sets.is_empty();
        let mut handoff = std::mem::take(&mut self.handoff);
        handoff.resize_with(bodies.apple_sets.len() + 1, Vec::new);
        handoff.iter_mut().for_each(Vec::clear);
        for &k in awake {
            let k = k as usize;
            if idle(k) {
                // Fell asleep in this pass, or rides a belt (rapier holds it asleep).
                continue;
            }
            let a = &apples[k];
            let (f, t) = match control {
                None => (self.force[k], self.torque[k]),
                Some(_) => {
                    let kick = if std::mem::take(&mut first_step[k]) {
                        0.5
                    } else {
                        kick
                    };
                    (
                        self.kicked_force[k] + gravity * (a.mass * (kick - 1.0)),
                        self.kicked_torque[k],
                    )
                }
            };
            let load = f != Vec3::ZERO || t != Vec3::ZERO;
            if !load && !self.loaded[k] {
                continue;
            }
            self.loaded[k] = load;
            if sets {
                handoff[a.body.set as usize].push((a.body.handle, f, t));
            } else if let Some(rb) = bodies.get_mut(a.body) {
                set_load(rb, f, t);
            }
        }
        if sets {
            let loads: usize = handoff.iter().map(Vec::len).sum();
            bodies.for_each_set(loads >= PARALLEL_MIN_READS, |set, rbs| {
                for &(h, f, t) in &handoff[set as usize] {
                    if let Some(rb) = rbs.get_mut(h) {
                        set_load(rb, f, t);
                    }
                }
            });
        }
        self.handoff = handoff;
        for (h, f, p) in self.body_loads.drain(..) {
            if let Some(rb) = bodies.main.get_mut(h) {
                if rb.is_dynamic() {
                    rb.add_force_at_point(f, p, true);
                }
            }
        }
    }
}

/// Replaces the force and torque on an apple's body (rapier keeps user forces across steps).
#[inline(always)]
fn set_load(rb: &mut rapier3d_f64::dynamics::RigidBody, f: Vec3, t: Vec3) {
    rb.reset_forces(false);
    rb.reset_torques(false);
    rb.add_force(f, false);
    rb.add_torque(t, false);
}
