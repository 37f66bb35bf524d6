//! The links of a scene file with their beads resolved: each bead's name,
//! the checks of a scene's beads (distinct names, no two overlapping where
//! they start) and of its rods, pins and springs.

use bevy::math::DVec2;

use super::{BeadPreset, ConstraintPreset, SpringPreset};
use crate::geometry::Coordinates;
use crate::preset::error::PresetError;
use crate::solver::{TOUCHING, overlapping};
use crate::validate::{ParamError, finite_vector, non_negative, positive};

/// Each bead's name, in order: its own, or `bead<i>`.
pub(in crate::preset) fn names_of<'a, V: Coordinates>(
    beads: impl Iterator<Item = &'a BeadPreset<V>>,
) -> Vec<String> {
    beads
        .enumerate()
        .map(|(i, b)| {
            if b.name.is_empty() {
                format!("bead{i}")
            } else {
                b.name.clone()
            }
        })
        .collect()
}

/// Checks a scene's beads (each wire's, then the free ones), that their
/// names are distinct, and its links; the links with their beads resolved.
pub(in crate::preset) fn check_beads_and_links<V: Coordinates>(
    wires: &[&[BeadPreset<V>]],
    free: &[BeadPreset<V>],
    constraints: &[ConstraintPreset<V>],
    springs: &[SpringPreset],
) -> Result<Vec<SceneLink<V>>, PresetError> {
    for (index, beads) in wires.iter().enumerate() {
        for (bead, preset) in beads.iter().enumerate() {
            preset.validate().map_err(|source| PresetError::Bead {
                wire: index,
                bead,
                source,
            })?;
        }
    }
    let names = names_of(wires.iter().copied().flatten().chain(free));
    let free_names = &names[names.len() - free.len()..];
    for (bead, name) in free.iter().zip(free_names) {
        bead.validate().map_err(|source| PresetError::FreeBead {
            name: name.clone(),
            source,
        })?;
    }
    for (i, name) in names.iter().enumerate() {
        if names[..i].contains(name) {
            return Err(PresetError::DuplicateName(name.clone()));
        }
    }
    let links = resolve_links(constraints, springs, &names)?;
    if names.is_empty() {
        return Err(PresetError::Empty);
    }
    let all: Vec<&BeadPreset<V>> = wires.iter().copied().flatten().chain(free).collect();
    if let Some((a, b, by)) = first_overlap(&all) {
        return Err(PresetError::Overlap {
            a: names[a].clone(),
            b: names[b].clone(),
            by,
        });
    }
    Ok(links)
}

/// The first two beads with radii that overlap where they start (by more
/// than rounding), and by how much: the pairs the broad phase finds among
/// the balls they would fill, measured.
fn first_overlap<V: Coordinates>(beads: &[&BeadPreset<V>]) -> Option<(usize, usize, f64)> {
    let round: Vec<usize> = (0..beads.len())
        .filter(|&i| beads[i].radius > 0.0)
        .collect();
    let boxes: Vec<_> = round
        .iter()
        .map(|&i| {
            let (at, r) = (beads[i].initial_position.xyz(), beads[i].radius);
            (at - r, at + r)
        })
        .collect();
    overlapping(&boxes).into_iter().find_map(|(k, l)| {
        let (i, j) = (round[k], round[l]);
        let (a, b) = (beads[i], beads[j]);
        let d = b.initial_position - a.initial_position;
        let reach = a.radius + b.radius;
        let by = reach - d.dot(d).sqrt();
        (by > TOUCHING * reach).then_some((i, j, by))
    })
}

/// The constraints, then the springs, with the beads they name as indices
/// into `names`, every value checked.
pub(in crate::preset) fn resolve_links<V: Coordinates>(
    constraints: &[ConstraintPreset<V>],
    springs: &[SpringPreset],
    names: &[String],
) -> Result<Vec<SceneLink<V>>, PresetError> {
    let find = |item: &dyn Fn() -> String, name: &str| {
        names
            .iter()
            .position(|n| n == name)
            .ok_or_else(|| PresetError::Link {
                item: item(),
                problem: format!("no bead is named {name:?}"),
            })
    };
    let problem = |item: String| {
        move |e: ParamError| PresetError::Link {
            item,
            problem: e.to_string(),
        }
    };
    let mut links = Vec::new();
    for (index, constraint) in constraints.iter().enumerate() {
        let item = || format!("constraint {index} ({})", constraint.kind());
        links.push(match constraint {
            ConstraintPreset::Rod(rod) => {
                let (a, b) = (find(&item, &rod.a)?, find(&item, &rod.b)?);
                if a == b {
                    return Err(problem(item())(ParamError::Incompatible(
                        "a rod must join two different beads",
                    )));
                }
                positive("rod length", rod.length).map_err(problem(item()))?;
                SceneLink::Rod {
                    a,
                    b,
                    length: rod.length,
                }
            }
            ConstraintPreset::Pin(pin) => {
                let bead = find(&item, &pin.bead)?;
                finite_vector("pin point", pin.at).map_err(problem(item()))?;
                SceneLink::Pin { bead, at: pin.at }
            }
            // Bodies', not beads': see `check_bodies` and `check_joins`.
            ConstraintPreset::Path(_)
            | ConstraintPreset::Hinge(_)
            | ConstraintPreset::Coupling(_) => continue,
        });
    }
    for (index, spring) in springs.iter().enumerate() {
        let item = || format!("spring {index}");
        let (a, b) = (find(&item, &spring.a)?, find(&item, &spring.b)?);
        if a == b {
            return Err(problem(item())(ParamError::Incompatible(
                "a spring must join two different beads",
            )));
        }
        for (name, value) in [
            ("spring rest length", spring.rest_length),
            ("spring stiffness", spring.stiffness),
            ("spring damping", spring.damping),
        ] {
            non_negative(name, value).map_err(problem(item()))?;
        }
        links.push(SceneLink::Spring {
            a,
            b,
            spring: spring.clone(),
        });
    }
    Ok(links)
}

/// A link of a scene with its beads as indices into
/// [`ScenePreset::all_beads`](super::ScenePreset::all_beads).
#[derive(Clone, Debug, PartialEq)]
pub enum SceneLink<V = DVec2> {
    /// A rod between beads `a` and `b`.
    Rod {
        /// The first bead.
        a: usize,
        /// The second bead.
        b: usize,
        /// Its length.
        length: f64,
    },
    /// A pin holding `bead` at `at`.
    Pin {
        /// The bead.
        bead: usize,
        /// The point.
        at: V,
    },
    /// A spring between beads `a` and `b`.
    Spring {
        /// The first bead.
        a: usize,
        /// The second bead.
        b: usize,
        /// Its law.
        spring: SpringPreset,
    },
}
