//! [`WireShape`]: a built-in shape or a game's own curve, and [`WireKind`],
//! the one list of built-in shapes that the panel, the scene files and the
//! analysis tool offer.

use std::fmt;
use std::str::FromStr;
use std::sync::Arc;

use bevy::math::DVec2;
use serde::{Deserialize, Serialize};

use super::traced::delegate_curve;
use super::{Circle, Cycloid, Ellipse, ImplicitCurve, Line, Parabola, Sine, Spline};
use crate::validate::{ParamError, finite, positive};

/// One of the built-in shapes, or a curve of the game's own.
#[derive(Clone, Serialize, Deserialize)]
pub enum WireShape {
    /// See [`Circle`].
    Circle(Circle),
    /// See [`Ellipse`].
    Ellipse(Ellipse),
    /// See [`Line`].
    Line(Line),
    /// See [`Parabola`].
    Parabola(Parabola),
    /// See [`Sine`].
    Sine(Sine),
    /// See [`Cycloid`].
    Cycloid(Cycloid),
    /// See [`Spline`]: a Bevy cubic curve.
    Spline(Spline),
    /// A game's own curve. Not serializable.
    #[serde(skip)]
    Custom(Arc<dyn ImplicitCurve + Send + Sync>),
}

impl fmt::Debug for WireShape {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Circle(s) => s.fmt(f),
            Self::Ellipse(s) => s.fmt(f),
            Self::Line(s) => s.fmt(f),
            Self::Parabola(s) => s.fmt(f),
            Self::Sine(s) => s.fmt(f),
            Self::Cycloid(s) => s.fmt(f),
            Self::Spline(s) => s.fmt(f),
            Self::Custom(_) => f.write_str("Custom(..)"),
        }
    }
}

impl WireShape {
    /// Checks the shape's dimensions: every length positive and finite
    /// (a sine's amplitude and a parabola's focal length may be negative).
    pub fn validate(&self) -> Result<(), ParamError> {
        match self {
            Self::Circle(c) => positive("radius", c.radius).map(drop),
            Self::Ellipse(e) => {
                positive("semi-axis a", e.a)?;
                positive("semi-axis b", e.b).map(drop)
            }
            Self::Line(_) | Self::Custom(_) => Ok(()),
            Self::Parabola(p) => {
                finite("focal length", p.focal_length)?;
                if p.focal_length == 0.0 {
                    return Err(ParamError::NotPositive {
                        name: "|focal length|",
                        value: p.focal_length,
                    });
                }
                Ok(())
            }
            Self::Sine(s) => {
                finite("amplitude", s.amplitude)?;
                positive("wavelength", s.wavelength).map(drop)
            }
            Self::Cycloid(c) => positive("cycloid radius", c.radius()).map(drop),
            // Checked when it was made.
            Self::Spline(_) => Ok(()),
        }
    }

    /// The shape as an [`ImplicitCurve`].
    pub fn curve(&self) -> &dyn ImplicitCurve {
        match self {
            Self::Circle(s) => s,
            Self::Ellipse(s) => s,
            Self::Line(s) => s,
            Self::Parabola(s) => s,
            Self::Sine(s) => s,
            Self::Cycloid(s) => s,
            Self::Spline(s) => s,
            Self::Custom(s) => s.as_ref(),
        }
    }

    /// Which way the wire's own direction runs against its unit tangent
    /// (see [`ImplicitCurve::travel`]).
    #[cfg_attr(not(feature = "avian2d"), allow(dead_code))]
    pub(crate) fn travel(&self) -> f64 {
        self.curve().travel()
    }

    /// The lowest point of the wire in its local frame (where a bead hangs
    /// at rest under gravity along local -y); the origin for shapes with no
    /// lowest point.
    pub fn bottom(&self) -> DVec2 {
        match self {
            Self::Circle(c) => DVec2::new(0.0, -c.radius),
            Self::Ellipse(e) => DVec2::new(0.0, -e.b),
            Self::Sine(s) => DVec2::new(-0.25 * s.wavelength, -s.amplitude),
            Self::Spline(s) => s.lowest(),
            Self::Line(_) | Self::Parabola(_) | Self::Cycloid(_) | Self::Custom(_) => DVec2::ZERO,
        }
    }

    /// Whether it is a parametric curve made a wire by its signed distance
    /// (a cycloid or a spline; see [`Traced`](super::Traced)).
    pub fn is_traced(&self) -> bool {
        matches!(self, Self::Cycloid(_) | Self::Spline(_))
    }

    /// The built-in kind of this shape; `None` for a custom curve.
    pub fn kind(&self) -> Option<WireKind> {
        match self {
            Self::Circle(_) => Some(WireKind::Circle),
            Self::Ellipse(_) => Some(WireKind::Ellipse),
            Self::Line(_) => Some(WireKind::Line),
            Self::Parabola(_) => Some(WireKind::Parabola),
            Self::Sine(_) => Some(WireKind::Sine),
            Self::Cycloid(_) => Some(WireKind::Cycloid),
            Self::Spline(_) | Self::Custom(_) => None,
        }
    }

    /// A short lowercase name: `circle`, `ellipse`, `line`, `parabola`,
    /// `sine`, `cycloid`, `spline` or `custom`.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Spline(_) => "spline",
            _ => self.kind().map_or("custom", WireKind::name),
        }
    }
}

/// The built-in shapes by name, each with a default proportion to one
/// characteristic size: the list the panel's menu, the scene files and the
/// analysis tool's `--wire` flag share.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum WireKind {
    /// A circle of radius `size`.
    #[default]
    Circle,
    /// An ellipse with semi-axes `1.5 size` and `size`.
    Ellipse,
    /// The horizontal line through the origin.
    Line,
    /// `y = x²/(4f)` with `f = size / 2` (vertex radius of curvature `size`).
    Parabola,
    /// `y = 0.3 size sin(2πx / (2 size))`.
    Sine,
    /// A cycloid of generating radius `size` (see [`Cycloid`]).
    Cycloid,
}

impl WireKind {
    /// Every kind, in the order a menu shows them.
    pub const ALL: [WireKind; 6] = [
        WireKind::Circle,
        WireKind::Ellipse,
        WireKind::Line,
        WireKind::Parabola,
        WireKind::Sine,
        WireKind::Cycloid,
    ];

    /// The lowercase name used on the command line and in the panel.
    pub fn name(self) -> &'static str {
        match self {
            Self::Circle => "circle",
            Self::Ellipse => "ellipse",
            Self::Line => "line",
            Self::Parabola => "parabola",
            Self::Sine => "sine",
            Self::Cycloid => "cycloid",
        }
    }

    /// The shape of this kind with characteristic size `size`.
    pub fn shape(self, size: f64) -> WireShape {
        match self {
            Self::Circle => WireShape::Circle(Circle { radius: size }),
            Self::Ellipse => WireShape::Ellipse(Ellipse {
                a: 1.5 * size,
                b: size,
            }),
            Self::Line => WireShape::Line(Line),
            Self::Parabola => WireShape::Parabola(Parabola {
                focal_length: 0.5 * size,
            }),
            Self::Sine => WireShape::Sine(Sine {
                amplitude: 0.3 * size,
                wavelength: 2.0 * size,
            }),
            Self::Cycloid => WireShape::Cycloid(Cycloid::new(size)),
        }
    }
}

impl fmt::Display for WireKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for WireKind {
    type Err = ParamError;
    fn from_str(s: &str) -> Result<Self, ParamError> {
        Self::ALL
            .into_iter()
            .find(|kind| kind.name() == s)
            .ok_or_else(|| ParamError::UnknownChoice {
                kind: "wire",
                got: s.to_owned(),
                expected: Self::ALL.map(WireKind::name).join(", "),
            })
    }
}

delegate_curve!(WireShape, |this| this.curve(), this.curve().scale());

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shapes_refuse_bad_dimensions() {
        let err = WireShape::Circle(Circle { radius: 0.0 })
            .validate()
            .unwrap_err();
        assert_eq!(err.to_string(), "radius must be positive and finite, got 0");
        assert!(
            WireShape::Ellipse(Ellipse {
                a: 1.0,
                b: f64::NAN
            })
            .validate()
            .is_err()
        );
        assert!(
            WireShape::Parabola(Parabola { focal_length: 0.0 })
                .validate()
                .is_err()
        );
        assert!(
            WireShape::Sine(Sine {
                amplitude: 1.0,
                wavelength: -1.0
            })
            .validate()
            .is_err()
        );
        assert!(WireShape::Line(Line).validate().is_ok());
    }

    #[test]
    fn kinds_round_trip_through_their_names_and_shapes() {
        for kind in WireKind::ALL {
            assert_eq!(kind.name().parse::<WireKind>(), Ok(kind));
            assert_eq!(kind.shape(2.0).kind(), Some(kind));
            assert!(kind.shape(2.0).validate().is_ok());
        }
        assert!("spiral".parse::<WireKind>().is_err());
    }
}
