//! The chip line as the recorder draws it: [`imrs_scene::World`] for [`Sim`], turning the
//! simulation's own scene and events into the recorder's vocabulary.
//!
//! Why here and not in the recorder: only the simulation knows its layout (where the
//! conveyors run, what a robot or a pallet is called), and the recorder must not compile
//! the simulation to record a cell. The conversion runs only while something is recorded.

use std::time::Duration;

use imrs_scene::{
    Arm, BoxPose as DrawnBox, Conveyor, Fact, Feeder, Field, Layout, Link, Pallet, Scene as Drawn,
    Severity, World, ZoneChange,
};

use crate::event::{SimEvent, SimEventKind};
use crate::ids::Line;
use crate::layout::{EXIT_X, GATE_X, line_y};
use crate::scene::{BoxPose, Scene};
use crate::sim::Sim;

impl World for Sim {
    fn layout(&self) -> Layout {
        let conveyors = Line::ALL
            .iter()
            .map(|line| {
                let y = line_y(line.index());
                Conveyor {
                    name: format!("{line:?}"),
                    belt: DrawnBox {
                        centre: [(GATE_X + EXIT_X) / 2.0, y, -0.01],
                        half: [(EXIT_X - GATE_X) / 2.0, 0.12, 0.01],
                    },
                    label_at: [GATE_X - 0.3, y, 0.05],
                }
            })
            .collect();
        Layout { conveyors }
    }

    fn watch(&self, period: Duration, mut see: Box<dyn FnMut(&Drawn) + Send>) {
        Sim::watch(self, period, move |scene: &Scene| see(&drawn(scene)));
    }

    fn facts(&self, mut see: Box<dyn FnMut(&Fact) + Send>) {
        self.log().subscribe(move |event| see(&fact(event)));
    }
}

fn drawn_box(pose: BoxPose) -> DrawnBox {
    DrawnBox {
        centre: pose.centre,
        half: pose.half,
    }
}

/// The scene in the recorder's vocabulary.
fn drawn(scene: &Scene) -> Drawn {
    Drawn {
        at: scene.at.since_start(),
        arms: scene
            .arms
            .iter()
            .map(|arm| Arm {
                name: arm.robot.to_string(),
                links: arm
                    .links
                    .iter()
                    .map(|link| Link {
                        centre: link.centre,
                        yaw: link.yaw,
                        length: link.length,
                        radius: link.radius,
                    })
                    .collect(),
                in_zone: arm.in_zone,
            })
            .collect(),
        pallets: scene
            .pallets
            .iter()
            .map(|pallet| Pallet {
                name: pallet.pallet.to_string(),
                pose: drawn_box(pallet.pose),
                card: pallet.card,
                chips: pallet.chips,
            })
            .collect(),
        feeders: scene
            .feeders
            .iter()
            .map(|feeder| Feeder {
                name: feeder.id.to_string(),
                chip: feeder.chip,
                stock: feeder.stock,
                at: feeder.at,
            })
            .collect(),
        zone: Some(drawn_box(scene.zone)),
    }
}

/// A measured fact in the recorder's vocabulary: its kind and fields as `/sim/events`
/// carries them, collisions as errors, faults and jams as warnings, and the zone's comings
/// and goings.
fn fact(event: &SimEvent) -> Fact {
    let text = |value: String| Field::Text(value);
    let count = |value: u32| Field::Count(u64::from(value));
    let (kind, fields) = match &event.kind {
        SimEventKind::ZoneEntered { robot } => {
            ("zone_entered", vec![("robot", text(robot.to_string()))])
        }
        SimEventKind::ZoneLeft { robot } => ("zone_left", vec![("robot", text(robot.to_string()))]),
        SimEventKind::Collision { a, b, point } => (
            "collision",
            vec![
                ("robot", text(format!("{a} {b}"))),
                ("point", Field::Numbers(point.to_vec())),
            ],
        ),
        SimEventKind::PalletReleased { line, pallet } => (
            "pallet_released",
            vec![
                ("line", text(format!("{line:?}"))),
                ("pallet", count(pallet.0)),
            ],
        ),
        SimEventKind::PalletDone {
            line,
            pallet,
            chips,
        } => (
            "pallet_done",
            vec![
                ("line", text(format!("{line:?}"))),
                ("pallet", count(pallet.0)),
                ("chips", count(*chips)),
            ],
        ),
        SimEventKind::ChipInserted {
            line,
            pallet,
            chip,
            on_card,
        } => (
            "chip_inserted",
            vec![
                ("line", text(format!("{line:?}"))),
                ("pallet", count(pallet.0)),
                ("chip", count(*chip)),
                (
                    "on_card_mm",
                    Field::Numbers(vec![on_card[0] * 1000.0, on_card[1] * 1000.0]),
                ),
            ],
        ),
        SimEventKind::FeederRefilled { feeder, chips } => (
            "feeder_refilled",
            vec![
                ("feeder", count(u32::from(feeder.0))),
                ("chips", count(*chips)),
            ],
        ),
        SimEventKind::PalletInPlace { .. } => ("pallet_in_place", Vec::new()),
        SimEventKind::PalletJammed { .. } => ("pallet_jammed", Vec::new()),
        SimEventKind::PalletScrapped { .. } => ("pallet_scrapped", Vec::new()),
        SimEventKind::CardPlaced { .. } => ("card_placed", Vec::new()),
        SimEventKind::CardScrewed { .. } => ("card_screwed", Vec::new()),
        SimEventKind::FaultStruck { .. } => ("fault_struck", Vec::new()),
        // As recorded so far: an emptied feeder's kind on `/sim/events` is `other`.
        SimEventKind::FeederEmptied { .. } => ("other", Vec::new()),
    };
    let severity = match event.kind {
        SimEventKind::Collision { .. } => Some(Severity::Error),
        SimEventKind::FaultStruck { .. } | SimEventKind::PalletJammed { .. } => {
            Some(Severity::Warning)
        }
        _ => None,
    };
    let zone = match &event.kind {
        SimEventKind::ZoneEntered { robot } => Some(ZoneChange::Entered(robot.to_string())),
        SimEventKind::ZoneLeft { robot } => Some(ZoneChange::Left(robot.to_string())),
        _ => None,
    };
    Fact {
        at: event.at.since_start(),
        kind,
        text: event.to_string(),
        fields,
        severity,
        zone,
    }
}
