//! One line's roller conveyor: pallets moving at the conveyor's speed, stopped by the
//! stations' freeze relays and by the pallet ahead.

use imrs_ports::Instant;
use rapier3d::prelude::ColliderHandle;

use super::physics::Physics;
use crate::event::{SimEvent, SimEventKind};
use crate::ids::{Line, PalletId, Station};
use crate::layout::{
    CHIP_X, CONVEYOR_SPEED, EXIT_X, GATE_X, LOAD_X, PALLET_HALF, PALLET_PITCH, line_y,
};

/// Where each station holds its pallet.
const STATION_X: [f32; 2] = [LOAD_X, CHIP_X];

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum PalletState {
    /// On its way to station `next` (or, past the last, to the exit).
    Moving { next: usize },
    /// Held in place by a station's relay.
    Held(Station),
    /// Jammed at a station: it moves no more until taken off.
    Jammed(Station),
}

pub(crate) struct Pallet {
    pub(crate) id: PalletId,
    x: f32,
    pub(crate) state: PalletState,
    pub(crate) card: bool,
    pub(crate) screwed: bool,
    pub(crate) chips: u32,
    body: ColliderHandle,
}

pub(crate) struct Conveyor {
    line: Line,
    /// Front (furthest along) first.
    pallets: Vec<Pallet>,
    /// Stations where the next pallet to arrive jams.
    pub(crate) jam_next: [bool; 2],
}

impl Conveyor {
    pub(crate) fn new(line: Line) -> Self {
        Self {
            line,
            pallets: Vec::new(),
            jam_next: [false; 2],
        }
    }

    fn y(&self) -> f32 {
        line_y(self.line.index())
    }

    /// Whether the photocell past the gate sees a pallet: the line is backed up to the gate.
    pub(crate) fn photocell_blocked(&self) -> bool {
        self.pallets
            .last()
            .is_some_and(|last| last.x < GATE_X + PALLET_PITCH)
    }

    pub(crate) fn release(&mut self, id: PalletId, physics: &mut Physics) {
        let at = [GATE_X, self.y(), PALLET_HALF[2]];
        self.pallets.push(Pallet {
            id,
            x: GATE_X,
            state: PalletState::Moving { next: 0 },
            card: false,
            screwed: false,
            chips: 0,
            body: physics.add_pallet(at),
        });
    }

    pub(crate) fn is_moving(&self) -> bool {
        self.pallets
            .iter()
            .any(|pallet| matches!(pallet.state, PalletState::Moving { .. }))
    }

    /// The pallet a station's relay holds (or that jammed there).
    pub(crate) fn at_station(&mut self, station: Station) -> Option<&mut Pallet> {
        self.pallets.iter_mut().find(|pallet| {
            matches!(pallet.state, PalletState::Held(s) | PalletState::Jammed(s) if s == station)
        })
    }

    /// Lets the pallet held at `station` go on.
    pub(crate) fn free(&mut self, station: Station) -> Option<PalletId> {
        let pallet = self
            .pallets
            .iter_mut()
            .find(|pallet| pallet.state == PalletState::Held(station))?;
        pallet.state = PalletState::Moving {
            next: station.index() + 1,
        };
        Some(pallet.id)
    }

    /// Takes the pallet jammed at `station` off the line.
    pub(crate) fn scrap(&mut self, station: Station, physics: &mut Physics) -> Option<PalletId> {
        let index = self
            .pallets
            .iter()
            .position(|pallet| pallet.state == PalletState::Jammed(station))?;
        let pallet = self.pallets.remove(index);
        physics.remove_pallet(pallet.body);
        Some(pallet.id)
    }

    /// Takes off the line every pallet a station holds.
    pub(crate) fn scrap_held(&mut self, physics: &mut Physics) -> Vec<PalletId> {
        let mut scrapped = Vec::new();
        self.pallets.retain(|pallet| {
            let held = matches!(pallet.state, PalletState::Held(_));
            if held {
                physics.remove_pallet(pallet.body);
                scrapped.push(pallet.id);
            }
            !held
        });
        scrapped
    }

    /// Moves the pallets on by `seconds`, front first, recording arrivals and exits.
    pub(crate) fn advance(
        &mut self,
        seconds: f32,
        now: Instant,
        physics: &mut Physics,
        events: &mut Vec<SimEvent>,
    ) {
        let line = self.line;
        let y = self.y();
        let mut ahead: Option<f32> = None;
        let mut done = Vec::new();
        for (index, pallet) in self.pallets.iter_mut().enumerate() {
            if let PalletState::Moving { next } = pallet.state {
                let stop = STATION_X.get(next).copied().unwrap_or(f32::INFINITY);
                let behind = ahead.map_or(f32::INFINITY, |x| x - PALLET_PITCH);
                let x = (pallet.x + CONVEYOR_SPEED * seconds).min(stop).min(behind);
                pallet.x = x.max(pallet.x);
                if pallet.x >= stop {
                    let station = Station::ALL[next];
                    let kind = if std::mem::take(&mut self.jam_next[next]) {
                        pallet.state = PalletState::Jammed(station);
                        SimEventKind::PalletJammed {
                            line,
                            station,
                            pallet: pallet.id,
                        }
                    } else {
                        pallet.state = PalletState::Held(station);
                        SimEventKind::PalletInPlace {
                            line,
                            station,
                            pallet: pallet.id,
                        }
                    };
                    events.push(SimEvent { at: now, kind });
                }
                if pallet.x >= EXIT_X {
                    done.push(index);
                }
                physics.place_pallet(pallet.body, [pallet.x, y, PALLET_HALF[2]]);
            }
            ahead = Some(pallet.x);
        }
        for index in done.into_iter().rev() {
            let pallet = self.pallets.remove(index);
            physics.remove_pallet(pallet.body);
            events.push(SimEvent {
                at: now,
                kind: SimEventKind::PalletDone {
                    line,
                    pallet: pallet.id,
                    chips: pallet.chips,
                },
            });
        }
    }

    /// Every pallet on the line with its position, as rapier has it.
    /// The pallets on the line, front first.
    pub(crate) fn pallets(&self) -> impl Iterator<Item = &Pallet> {
        self.pallets.iter()
    }

    pub(crate) fn positions(&self, physics: &Physics) -> Vec<(PalletId, [f32; 3])> {
        self.pallets
            .iter()
            .map(|pallet| (pallet.id, physics.position_of(pallet.body)))
            .collect()
    }
}

impl Pallet {
    /// The pallet's collider, which rapier places.
    pub(crate) fn body(&self) -> ColliderHandle {
        self.body
    }
}
