//! The objects on the table, and what the camera reports of them.

use nalgebra::{Point3, UnitQuaternion};

/// The kinds of object the camera tells apart.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Shape {
    /// A cube.
    Cube,
    /// A ball.
    Ball,
    /// An upright cylinder.
    Cylinder,
}

/// An object to put on the table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Object {
    /// Its kind.
    pub shape: Shape,
    /// Its width: a cube's edge, a ball's or a cylinder's diameter. A cylinder stands
    /// `1.6 × size` tall.
    pub size: f32,
    /// Where its centre rests on the table (x, y).
    pub at: [f32; 2],
}

impl Object {
    /// The object's height.
    pub fn height(&self) -> f32 {
        match self.shape {
            Shape::Cube | Shape::Ball => self.size,
            Shape::Cylinder => 1.6 * self.size,
        }
    }
}

/// One separable object as the camera sees it this frame: features only, no identity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Detection {
    /// Where its centre is.
    pub position: Point3<f32>,
    /// How it is turned.
    pub orientation: UnitQuaternion<f32>,
    /// Its kind.
    pub shape: Shape,
    /// Its width, as [`Object::size`].
    pub size: f32,
}

/// The table's objects in the default scene: a cube, a ball and a cylinder of different
/// widths, apart from each other.
pub const SCENE: [Object; 3] = [
    Object {
        shape: Shape::Cube,
        size: 0.05,
        at: [0.0, 0.0],
    },
    Object {
        shape: Shape::Ball,
        size: 0.06,
        at: [0.18, 0.12],
    },
    Object {
        shape: Shape::Cylinder,
        size: 0.045,
        at: [-0.18, 0.12],
    },
];
