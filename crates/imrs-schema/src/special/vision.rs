//! The vision interface: tells objects apart from frame to frame and keeps one `SEF` per
//! object.

use std::sync::{Arc, Mutex, PoisonError};
use std::time::Duration;

use imrs_sim::hand::{Detection, Hand};

use super::feature::{Seen, Sef};
use crate::{Behavior, Cx, Flow, Schema, SchemaError, Si};

/// One object the interface keeps track of.
#[derive(Debug)]
pub(crate) struct Track {
    sef: Si<Sef>,
    seen: Seen,
    last: Detection,
    missed: u32,
}

/// The vision interface, as a schema with no ports: every [`Vision::FRAME`] it looks
/// ([`Hand::see`]), matches each detection to the object it was last frame — the same
/// shape, nearest, within [`Vision::GATE`] — and keeps `SEF_k` for object `k`: made when an
/// object first appears, stopped once it has been missed [`Vision::LOST`] frames in a row.
/// Numbers are never reused, so `SEF_k` always stands for the same object. The price: each
/// object ever seen keeps its name `SEF_k` for the life of the process (names are
/// interned), so a camera that sees new objects without end grows by one name per object.
#[derive(Debug)]
pub struct Vision {
    hand: Hand,
    tracks: Vec<Track>,
    next: u32,
}

impl Vision {
    /// How often the camera looks.
    pub const FRAME: Duration = Duration::from_millis(50);
    /// The farthest an object is taken to move between two frames, in metres.
    pub const GATE: f32 = 0.05;
    /// How many frames in a row an object may be missed before its SEF is stopped.
    pub const LOST: u32 = 3;

    /// A vision interface on `hand`'s camera.
    pub fn new(hand: &Hand) -> Self {
        Self {
            hand: hand.clone(),
            tracks: Vec::new(),
            next: 1,
        }
    }

    /// Matches this frame's detections to the tracks; returns the detections no track took.
    fn follow(&mut self, mut seen: Vec<Detection>) -> Vec<Detection> {
        for track in &mut self.tracks {
            let nearest = seen
                .iter()
                .enumerate()
                .filter(|(_, d)| d.shape == track.last.shape)
                .map(|(i, d)| (i, (d.position - track.last.position).norm()))
                .filter(|&(_, distance)| distance <= Self::GATE)
                .min_by(|a, b| a.1.total_cmp(&b.1));
            match nearest {
                Some((i, _)) => {
                    track.last = seen.swap_remove(i);
                    track.missed = 0;
                    *track.seen.lock().unwrap_or_else(PoisonError::into_inner) = Some(track.last);
                }
                None => track.missed += 1,
            }
        }
        seen
    }
}

impl Schema for Vision {
    const NAME: &'static str = "Vision";
    type Ports = ();

    fn set_up(&mut self, _: &Cx) -> Result<(), SchemaError> {
        Ok(())
    }

    async fn behavior(&mut self, _: &(), cx: &Cx) -> Behavior {
        let fresh = self.follow(self.hand.see());
        for track in self.tracks.iter().filter(|t| t.missed >= Self::LOST) {
            *track.seen.lock().unwrap_or_else(PoisonError::into_inner) = None;
            track.sef.stop();
        }
        self.tracks.retain(|t| t.missed < Self::LOST);
        // New objects in a fixed order (by position), so that numbering is reproducible
        // whatever order the camera reported them in.
        let mut fresh = fresh;
        fresh.sort_by(|a, b| {
            (a.position.x, a.position.y)
                .partial_cmp(&(b.position.x, b.position.y))
                .unwrap_or(std::cmp::Ordering::Equal)
        });
        for detection in fresh {
            let seen = Arc::new(Mutex::new(Some(detection)));
            let sef = cx.instantiate_as(self.next, Sef::new(&self.hand, Arc::clone(&seen)))?;
            self.next += 1;
            self.tracks.push(Track {
                sef,
                seen,
                last: detection,
                missed: 0,
            });
        }
        cx.delay(Self::FRAME).await;
        Ok(Flow::Continue)
    }
}
