//! The geometric check of an arm's way ahead (Jiménez et al. 1992): waiting until the other
//! arms are out of the way, going round those that stay, or backing off.

use std::collections::VecDeque;
use std::time::Duration;

use imrs_ports::Name;
use nalgebra::Point2;

use super::{BACK_OFF_AFTER, DETOUR_AFTER, Driver, Got, LOOKAHEAD, Leg, RETRY, SPACING};
use crate::lock;
use imrs_coord::coordinator::Message;
use imrs_coord::zones::Pipeline;

impl Driver {
    /// Waits until the arm's links at `ahead` keep clear of every other arm (as the
    /// coordinator checks them against where the others told it they are), freeing
    /// meanwhile what it holds but is not inside (and its right to move in a shared zone
    /// it is in), so that whoever is in its way can move; asks for them again before it
    /// goes on. Or gives up the leg: round the arms in the way, or back.
    pub(super) async fn clear(
        &mut self,
        ahead: &[Point2<f32>],
        leg_end: &Point2<f32>,
        (pipeline, allowed): (&Pipeline, &mut VecDeque<(f32, Vec<Name>)>),
        may_back_off: bool,
    ) -> Result<Option<Leg>, String> {
        let mut freed: Vec<Name> = Vec::new();
        let mut waited = Duration::ZERO;
        // Whether it is stopped and holds only what it is in: then it says it waits.
        let mut waiting = false;
        loop {
            // Once stopped and freed of what it is not in, it says it waits.
            let blocking = if waiting {
                self.waiting_on(ahead).await?
            } else {
                self.blockers(ahead).await?
            };
            if blocking.is_empty() {
                if freed.is_empty() {
                    return Ok(None);
                }
                // The exclusive zones and the tool first, while it moves in no shared zone;
                // then the shared ones, so that it never sleeps at a border holding a
                // right to move.
                let (shared, exclusive): (Vec<Name>, Vec<Name>) = std::mem::take(&mut freed)
                    .into_iter()
                    .partition(|zone| self.is_shared(zone));
                let mut got = Got::Granted;
                for zone in exclusive {
                    if got == Got::Granted {
                        got = self.acquire(&zone).await?;
                    }
                }
                if got == Got::Granted {
                    got = self.reacquire_shared(shared).await?;
                }
                if got == Got::BackOff {
                    // The victim of a deadlock: out of the way, home.
                    return Ok(Some(Leg::Victim));
                }
                waiting = false;
                // The others may have moved while this arm waited for its zones.
                continue;
            }
            if waited.is_zero() {
                lock(&self.stats).geometric_blocks += 1;
                // It cannot stop at once: it brakes along the points it was allowed, which
                // were checked with its stopping distance to spare; the zones it left at
                // the points it reached meanwhile, it releases.
                self.halt().await?;
                self.track(allowed).await?;
            }
            // Whatever it holds and is not inside, and its right to move where it is in a
            // shared zone, it frees while it waits — every time it finds itself blocked,
            // also after it asked for them again — so that no arm waits on it for a zone
            // while it waits on that arm for space.
            let inside = self.zones_at(self.arm.at());
            for zone in pipeline.holding().cloned().collect::<Vec<_>>() {
                if freed.contains(&zone) {
                    continue;
                }
                if !inside.contains(&zone) {
                    self.tell(Message::Release(zone.clone())).await?;
                    freed.push(zone);
                } else if self.is_shared(&zone) {
                    self.tell(Message::Position(zone.clone())).await?;
                    freed.push(zone);
                }
            }
            waiting = true;
            if waited >= DETOUR_AFTER
                && let Some(points) = self.round(&blocking, leg_end).await?
            {
                lock(&self.stats).detours += 1;
                return Ok(Some(Leg::Via(points)));
            }
            // Two arms in each other's way: the later-named backs off; if it cannot, the
            // other does, after twice as long. On a way round or back, it may back off
            // again only after long: two arms that cannot part otherwise.
            let my_turn =
                blocking.iter().all(|other| *other < self.name) || waited >= 2 * BACK_OFF_AFTER;
            let may = may_back_off || waited >= 4 * BACK_OFF_AFTER;
            if waited >= BACK_OFF_AFTER
                && may
                && my_turn
                && let Some(point) = self.back_point(leg_end).await?
            {
                lock(&self.stats).back_offs += 1;
                return Ok(Some(Leg::BackOff(point)));
            }
            self.ctx.delay(RETRY).await;
            waited += RETRY;
        }
    }

    /// The coordinator's alternative trajectory round the arms in the way, from here to the
    /// leg's end, if this arm reaches its every point and the coordinator finds its links
    /// clear of every other arm all the way.
    async fn round(
        &mut self,
        blocking: &[Name],
        leg_end: &Point2<f32>,
    ) -> Result<Option<Vec<Point2<f32>>>, String> {
        let here = self.arm.at();
        let way = self
            .link
            .alternative([here.x, here.y], [leg_end.x, leg_end.y], blocking.to_vec())
            .await
            .map_err(|refused| format!("{refused:?}"))?;
        let Some(way) = way else {
            return Ok(None);
        };
        let points: Vec<Point2<f32>> = way.iter().map(|p| Point2::new(p[0], p[1])).collect();
        // Check the whole way, every spacing, links and all.
        let sampled: Vec<Point2<f32>> = points
            .windows(2)
            .flat_map(|pair| {
                let n = ((pair[1] - pair[0]).norm() / SPACING).ceil().max(1.0) as usize;
                (0..=n).map(move |i| pair[0] + (pair[1] - pair[0]) * (i as f32 / n as f32))
            })
            .collect();
        if !sampled.iter().all(|p| self.scara.reaches(p)) {
            return Ok(None);
        }
        let clear = self.blockers(&sampled).await?.is_empty();
        Ok(clear.then(|| points[1..].to_vec()))
    }

    /// Where to back off to, away from `leg_end`: home, if the coordinator finds the first
    /// steps there clear; else a short way back, or to either side, whichever it finds
    /// clear all the way (home may lie past the arm in the way).
    async fn back_point(&mut self, leg_end: &Point2<f32>) -> Result<Option<Point2<f32>>, String> {
        let here = self.arm.at();
        let towards = self.home - here;
        if towards.norm() >= SPACING {
            let step = towards.normalize() * SPACING;
            let first: Vec<Point2<f32>> = (1..=LOOKAHEAD).map(|i| here + step * i as f32).collect();
            if self.blockers(&first).await?.is_empty() {
                return Ok(Some(self.home));
            }
        }
        let ahead = *leg_end - here;
        if ahead.norm() < SPACING {
            return Ok(None);
        }
        let back = -ahead.normalize();
        let side = nalgebra::Vector2::new(-back.y, back.x);
        for direction in [back, side, -side] {
            let way: Vec<Point2<f32>> = (1..=LOOKAHEAD)
                .map(|i| here + direction * (SPACING * i as f32))
                .collect();
            if way.iter().all(|p| self.scara.reaches(p)) && self.blockers(&way).await?.is_empty() {
                return Ok(way.last().copied());
            }
        }
        Ok(None)
    }
}
