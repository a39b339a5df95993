//! The simulated scene in Foxglove's well-known schemas, so that the 3D panel shows the cell
//! moving with no set-up: every arm link and every pallet is a frame
//! (`foxglove.FrameTransforms` on `/tf`, at each sample) carrying a shape that follows it;
//! the shapes themselves, and the parts that change otherwise — pallets coming and going,
//! their cards and chips, the feeders' stock, the zone tinted by who is inside — are
//! `foxglove.SceneUpdate`s, sent only when they change. A moving cell thus costs a few
//! transforms per sample, not its whole scene.
//!
//! What is drawn comes from the world through [`imrs_scene::World`]: its conveyors, arms,
//! pallets, feeders and zone, with their names. Nothing here knows one world's layout, so
//! recording a cell compiles no simulation.

use std::collections::HashMap;

use foxglove::messages::{
    Color, CubePrimitive, CylinderPrimitive, FrameTransform, FrameTransforms, KeyValuePair, Pose,
    Quaternion, SceneEntity, SceneEntityDeletion, SceneUpdate, TextPrimitive, Vector3,
    scene_entity_deletion::Type as Deletion,
};
use imrs_scene::{BoxPose, Feeder, Layout, Pallet, Scene};

use crate::time::stamp;

/// The frame everything else hangs from.
pub const WORLD: &str = "world";

/// The frame of a pallet: its name.
pub fn pallet_frame(pallet: &Pallet) -> String {
    pallet.name.clone()
}

/// The frame of link `index` (from 0, the base's) of the arm named `arm`.
pub fn link_frame(arm: impl std::fmt::Display, index: usize) -> String {
    format!("{arm}/link{}", index + 1)
}

fn vector(v: [f32; 3]) -> Vector3 {
    Vector3 {
        x: f64::from(v[0]),
        y: f64::from(v[1]),
        z: f64::from(v[2]),
    }
}

fn yaw(angle: f32) -> Quaternion {
    let half = f64::from(angle) / 2.0;
    Quaternion {
        x: 0.0,
        y: 0.0,
        z: half.sin(),
        w: half.cos(),
    }
}

const IDENTITY: Quaternion = Quaternion {
    x: 0.0,
    y: 0.0,
    z: 0.0,
    w: 1.0,
};

fn rgba(r: f64, g: f64, b: f64, a: f64) -> Option<Color> {
    Some(Color { r, g, b, a })
}

fn entity(scene: &Scene, frame: &str, id: String) -> SceneEntity {
    SceneEntity {
        timestamp: Some(stamp(scene.at)),
        frame_id: frame.into(),
        id,
        ..SceneEntity::default()
    }
}

fn cube(pose: &BoxPose, color: Option<Color>) -> CubePrimitive {
    CubePrimitive {
        pose: Some(Pose {
            position: Some(vector(pose.centre)),
            orientation: Some(IDENTITY),
        }),
        size: Some(vector(pose.half.map(|half| 2.0 * half))),
        color,
    }
}

/// The parts that never move, sent once: the layout's conveyors, and each arm link's shape
/// in the link's own frame (`frame_locked`, so it follows the frame's transforms), stamped
/// with the first `scene`.
pub fn fixed(layout: &Layout, scene: &Scene) -> SceneUpdate {
    let mut entities = Vec::new();
    for line in &layout.conveyors {
        let mut conveyor = entity(scene, WORLD, format!("conveyor-{}", line.name));
        conveyor
            .cubes
            .push(cube(&line.belt, rgba(0.35, 0.35, 0.38, 1.0)));
        conveyor.texts.push(TextPrimitive {
            pose: Some(Pose {
                position: Some(vector(line.label_at)),
                orientation: Some(IDENTITY),
            }),
            billboard: true,
            font_size: 14.0,
            scale_invariant: true,
            color: rgba(1.0, 1.0, 1.0, 1.0),
            text: format!("line {}", line.name),
        });
        entities.push(conveyor);
    }
    for arm in &scene.arms {
        for (index, link) in arm.links.iter().enumerate() {
            let frame = link_frame(&arm.name, index);
            let mut shape = entity(scene, &frame, frame.clone());
            shape.frame_locked = true;
            let diameter = f64::from(2.0 * link.radius);
            // A cylinder's axis is its z: turned a quarter about y, it lies along the link.
            let along_x = Quaternion {
                x: 0.0,
                y: std::f64::consts::FRAC_1_SQRT_2,
                z: 0.0,
                w: std::f64::consts::FRAC_1_SQRT_2,
            };
            shape.cylinders.push(CylinderPrimitive {
                pose: Some(Pose {
                    position: Some(vector([0.0; 3])),
                    orientation: Some(along_x),
                }),
                size: Some(Vector3 {
                    x: diameter,
                    y: diameter,
                    z: f64::from(link.length + 2.0 * link.radius),
                }),
                bottom_scale: 1.0,
                top_scale: 1.0,
                color: rgba(0.95, 0.6, 0.1, 1.0),
            });
            shape.metadata.push(KeyValuePair {
                key: "robot".into(),
                value: arm.name.clone(),
            });
            entities.push(shape);
        }
    }
    SceneUpdate {
        deletions: Vec::new(),
        entities,
    }
}

/// The frames last sent, so that a sample sends only the frames that moved: Foxglove keeps a
/// frame where it was last put.
#[derive(Debug, Default)]
pub struct Moved {
    links: Vec<([f32; 3], f32)>,
    pallets: HashMap<String, [f32; 3]>,
}

impl Moved {
    /// The transforms of the frames that moved since the last call (all, the first time);
    /// `None` when nothing moved.
    pub fn since_last(&mut self, scene: &Scene) -> Option<FrameTransforms> {
        let mut moved = Vec::new();
        let first = self.links.is_empty();
        let mut index = 0;
        for arm in &scene.arms {
            for (link_index, link) in arm.links.iter().enumerate() {
                let pose = (link.centre, link.yaw);
                if first {
                    self.links.push(pose);
                } else if self.links.get(index) == Some(&pose) {
                    index += 1;
                    continue;
                } else if let Some(last) = self.links.get_mut(index) {
                    *last = pose;
                }
                index += 1;
                moved.push(FrameTransform {
                    timestamp: Some(stamp(scene.at)),
                    parent_frame_id: WORLD.into(),
                    child_frame_id: link_frame(&arm.name, link_index),
                    translation: Some(vector(link.centre)),
                    rotation: Some(yaw(link.yaw)),
                });
            }
        }
        self.pallets
            .retain(|name, _| scene.pallets.iter().any(|p| p.name == *name));
        for pallet in &scene.pallets {
            let centre = pallet.pose.centre;
            if self.pallets.insert(pallet.name.clone(), centre) == Some(centre) {
                continue;
            }
            moved.push(FrameTransform {
                timestamp: Some(stamp(scene.at)),
                parent_frame_id: WORLD.into(),
                child_frame_id: pallet_frame(pallet),
                translation: Some(vector(centre)),
                rotation: Some(IDENTITY),
            });
        }
        (!moved.is_empty()).then_some(FrameTransforms { transforms: moved })
    }
}

/// The parts as last sent, so that an update carries only the parts that changed: a pallet
/// that came, left, or got its card or a chip; a feeder whose stock changed; the zone when
/// who is inside changed.
#[derive(Debug, Default)]
pub struct Parts {
    sent: bool,
    pallets: HashMap<String, (bool, u32)>,
    stocks: Vec<u32>,
    inside: Option<usize>,
}

impl Parts {
    /// The update that brings the parts sent so far to `scene`'s; `None` when none changed.
    pub fn since_last(&mut self, scene: &Scene) -> Option<SceneUpdate> {
        let mut update = SceneUpdate::default();
        let first = !std::mem::replace(&mut self.sent, true);
        for pallet in &scene.pallets {
            let state = (pallet.card, pallet.chips);
            if self.pallets.insert(pallet.name.clone(), state) != Some(state) {
                update.entities.push(pallet_entity(scene, pallet));
            }
        }
        let gone: Vec<String> = self
            .pallets
            .keys()
            .filter(|name| !scene.pallets.iter().any(|p| p.name == **name))
            .cloned()
            .collect();
        for name in gone {
            self.pallets.remove(&name);
            update.deletions.push(SceneEntityDeletion {
                timestamp: Some(stamp(scene.at)),
                r#type: Deletion::MatchingId as i32,
                id: name,
            });
        }
        for (index, feeder) in scene.feeders.iter().enumerate() {
            if first || self.stocks.get(index) != Some(&feeder.stock) {
                update.entities.push(feeder_entity(scene, feeder));
            }
        }
        self.stocks = scene.feeders.iter().map(|f| f.stock).collect();
        let inside = scene.arms.iter().filter(|arm| arm.in_zone).count();
        if let Some(zone) = &scene.zone
            && self.inside != Some(inside)
        {
            self.inside = Some(inside);
            update.entities.push(zone_entity(scene, zone, inside));
        }
        (first || !update.entities.is_empty() || !update.deletions.is_empty()).then_some(update)
    }
}

/// A pallet, in its own frame: grey when bare, green with a card, brighter for each chip.
fn pallet_entity(scene: &Scene, pallet: &Pallet) -> SceneEntity {
    let frame = pallet_frame(pallet);
    let mut shape = entity(scene, &frame, frame.clone());
    shape.frame_locked = true;
    let color = if pallet.card {
        let chips = f64::from(pallet.chips.min(4)) / 4.0;
        rgba(0.1, 0.45 + 0.5 * chips, 0.2, 1.0)
    } else {
        rgba(0.6, 0.6, 0.6, 1.0)
    };
    let at_frame = BoxPose {
        centre: [0.0; 3],
        half: pallet.pose.half,
    };
    shape.cubes.push(cube(&at_frame, color));
    shape.metadata.push(KeyValuePair {
        key: "chips".into(),
        value: pallet.chips.to_string(),
    });
    shape
}

/// A feeder, red when empty, with its chip number and stock.
fn feeder_entity(scene: &Scene, feeder: &Feeder) -> SceneEntity {
    let mut shape = entity(scene, WORLD, feeder.name.clone());
    let empty = feeder.stock == 0;
    shape.cylinders.push(CylinderPrimitive {
        pose: Some(Pose {
            position: Some(vector([feeder.at[0], feeder.at[1], 0.05])),
            orientation: Some(IDENTITY),
        }),
        size: Some(Vector3 {
            x: 0.06,
            y: 0.06,
            z: 0.1,
        }),
        bottom_scale: 1.0,
        top_scale: 1.0,
        color: if empty {
            rgba(0.9, 0.1, 0.1, 1.0)
        } else {
            rgba(0.2, 0.4, 0.9, 1.0)
        },
    });
    shape.texts.push(TextPrimitive {
        pose: Some(Pose {
            position: Some(vector([feeder.at[0], feeder.at[1], 0.15])),
            orientation: Some(IDENTITY),
        }),
        billboard: true,
        font_size: 12.0,
        scale_invariant: true,
        color: rgba(1.0, 1.0, 1.0, 1.0),
        text: format!("chip {}: {}", feeder.chip, feeder.stock),
    });
    shape
}

/// The feeder zone: clear when empty, amber with one robot inside, red with more.
fn zone_entity(scene: &Scene, zone_box: &BoxPose, inside: usize) -> SceneEntity {
    let mut zone = entity(scene, WORLD, "feeder-zone".into());
    let color = match inside {
        0 => rgba(0.3, 0.6, 1.0, 0.15),
        1 => rgba(1.0, 0.7, 0.1, 0.3),
        _ => rgba(1.0, 0.1, 0.1, 0.5),
    };
    zone.cubes.push(cube(zone_box, color));
    zone.metadata.push(KeyValuePair {
        key: "robots inside".into(),
        value: inside.to_string(),
    });
    zone
}
