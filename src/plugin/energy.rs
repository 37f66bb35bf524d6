//! [`SceneEnergy`]: the energy of the whole scene after each step, for a
//! plot a user can trust where islands gain and lose beads.

use bevy::math::DVec3;
use bevy::prelude::*;

use super::clock::SimClock;
use super::islands::{InIsland, Islands};
use crate::dynamics::{BeadMass, BeadPosition, BeadVelocity, SimParams};
use crate::geometry::Coordinates;
use crate::solver::BeadState;

/// The scene's energy after the last step: the kinetic and gravitational
/// energy of every bead, in the plane and in space, the energy stored in
/// the springs between beads, and, where an avian `PathJointPlugin` is
/// added, the kinetic (turning included) and gravitational energy of
/// every dynamic body of avian under avian's gravity, after avian's
/// step. It changes only by what damping,
/// friction, inelastic strikes and landings, drift, a drag and moving
/// wires take or give. An island's own energy
/// ([`IslandReport::energy`](crate::plugin::IslandReport)) jumps where
/// the island gains or loses beads as contacts close and open; this does
/// not.
///
/// Kept up to date after each step where the app has the resource (the
/// window adds it); a game that wants it adds it too:
///
/// ```
/// use bevy::prelude::*;
/// use wirebead::SceneEnergy;
/// use wirebead::prelude::*;
///
/// let mut app = App::new();
/// app.add_plugins((MinimalPlugins, WireBeadPlugin::default()))
///     .init_resource::<SceneEnergy>();
/// ```
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Reflect)]
#[reflect(Resource)]
pub struct SceneEnergy {
    /// The energy, J.
    pub total: f64,
    /// The simulated time it was measured at, s.
    pub time: f64,
}

/// Measures [`SceneEnergy`]: each island's energy (its beads' and its
/// springs'), and each bead stepped alone on its wire, in the plane and
/// in space.
pub(super) fn measure_scene_energy(
    mut energy: ResMut<SceneEnergy>,
    params: Res<SimParams>,
    clock: Res<SimClock>,
    (islands, space_islands): (Res<Islands>, Res<Islands<DVec3>>),
    alone: Query<(&BeadPosition, &BeadVelocity, &BeadMass), Without<InIsland>>,
    alone_in_space: Query<
        (&BeadPosition<DVec3>, &BeadVelocity<DVec3>, &BeadMass),
        Without<InIsland>,
    >,
) {
    let joined = islands.energy() + space_islands.energy();
    let lone: f64 = alone
        .iter()
        .map(|(x, v, m)| bead_energy(x.0, v.0, m.get(), params.gravity))
        .chain(
            alone_in_space
                .iter()
                .map(|(x, v, m)| bead_energy(x.0, v.0, m.get(), params.gravity_in_space())),
        )
        .sum();
    *energy = SceneEnergy {
        total: joined + lone,
        time: clock.time,
    };
}

/// A bead's kinetic and gravitational energy, of `mass` at `position`
/// moving at `velocity` under `gravity`.
fn bead_energy<V: Coordinates>(position: V, velocity: V, mass: f64, gravity: V) -> f64 {
    let (kinetic, potential) = BeadState { position, velocity }.energy(mass, gravity);
    kinetic + potential
}
