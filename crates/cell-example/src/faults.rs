//! The faults an operator can inject with `--fault KIND[:WHICH]@TIME`, and their injection
//! into a run.

use std::fmt;
use std::str::FromStr;
use std::sync::PoisonError;
use std::time::Duration;

use imrs_ports::Instant;
use imrs_sim::{Fault, FaultKind, FeederId, Line, RobotId, Role, Sim, Station};

use crate::gate::ReleaseDeath;

/// A fault to inject into a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CellFault {
    /// What goes wrong.
    pub kind: CellFaultKind,
    /// When, from the start of the run.
    pub at: Duration,
}

/// What goes wrong.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CellFaultKind {
    /// GATE's RELEASE task dies (`release[:A|B]`).
    ReleaseDies(Line),
    /// The chip robot faults in mid-operation (`robot[:A|B]`).
    RobotFault(Line),
    /// A feeder runs empty (`feeder[:0-3]`).
    FeederEmpty(FeederId),
    /// A pallet jams at the load station's freeze relay (`jam[:A|B]`).
    PalletJam(Line),
}

/// Why a `--fault` value was refused.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FaultParseError {
    value: String,
    why: &'static str,
}

impl fmt::Display for FaultParseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "--fault {:?}: {} (expected KIND[:WHICH]@TIME, KIND one of release, robot, feeder, jam; \
             WHICH a line A or B, or a feeder 0 to 3; TIME in seconds, or with s, m or h, e.g. robot:B@15m)",
            self.value, self.why
        )
    }
}

impl FaultParseError {
    /// What was wrong and the syntax expected, without the flag and the value (for a parser
    /// that names them itself).
    pub fn reason(&self) -> String {
        let full = self.to_string();
        let prefix = format!("--fault {:?}: ", self.value);
        full.strip_prefix(&prefix).unwrap_or(&full).to_string()
    }
}

impl std::error::Error for FaultParseError {}

/// The latest time a fault may be set for: a year.
const MAX_FAULT_SECONDS: f64 = 365.0 * 24.0 * 3600.0;

fn parse_time(text: &str) -> Option<Duration> {
    let (number, unit) = match text.char_indices().last()? {
        (at, 's') => (&text[..at], 1.0),
        (at, 'm') => (&text[..at], 60.0),
        (at, 'h') => (&text[..at], 3600.0),
        _ => (text, 1.0),
    };
    let seconds = number.parse::<f64>().ok()? * unit;
    // Beyond a year no run reaches it; the bound also keeps `Duration` from overflowing.
    (seconds.is_finite() && (0.0..=MAX_FAULT_SECONDS).contains(&seconds))
        .then(|| Duration::from_secs_f64(seconds))
}

fn parse_line(which: Option<&str>) -> Option<Line> {
    match which {
        None | Some("A") | Some("a") => Some(Line::A),
        Some("B") | Some("b") => Some(Line::B),
        Some(_) => None,
    }
}

impl FromStr for CellFault {
    type Err = FaultParseError;

    fn from_str(value: &str) -> Result<Self, Self::Err> {
        let refuse = |why| FaultParseError {
            value: value.to_string(),
            why,
        };
        let (what, time) = value.split_once('@').ok_or_else(|| refuse("no @TIME"))?;
        let at = parse_time(time).ok_or_else(|| {
            refuse("the time is not a number of seconds, minutes or hours within a year")
        })?;
        let (kind, which) = match what.split_once(':') {
            Some((kind, which)) => (kind, Some(which)),
            None => (what, None),
        };
        let line = || parse_line(which).ok_or_else(|| refuse("the line must be A or B"));
        let kind = match kind {
            "release" => CellFaultKind::ReleaseDies(line()?),
            "robot" => CellFaultKind::RobotFault(line()?),
            "jam" => CellFaultKind::PalletJam(line()?),
            "feeder" => {
                let feeder: u8 = which
                    .unwrap_or("0")
                    .parse()
                    .map_err(|_| refuse("the feeder must be 0 to 3"))?;
                if feeder > 3 {
                    return Err(refuse("the feeder must be 0 to 3"));
                }
                CellFaultKind::FeederEmpty(FeederId(feeder))
            }
            _ => return Err(refuse("unknown kind")),
        };
        Ok(Self { kind, at })
    }
}

impl fmt::Display for CellFault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let at = self.at.as_secs_f64();
        match self.kind {
            CellFaultKind::ReleaseDies(line) => write!(f, "release:{line:?}@{at}s"),
            CellFaultKind::RobotFault(line) => write!(f, "robot:{line:?}@{at}s"),
            CellFaultKind::FeederEmpty(feeder) => write!(f, "feeder:{}@{at}s", feeder.0),
            CellFaultKind::PalletJam(line) => write!(f, "jam:{line:?}@{at}s"),
        }
    }
}

/// Sets `faults` to happen in `sim`; a RELEASE death goes to its line's GATE through
/// `deaths`, as the simulation does not run GATE.
pub(crate) fn inject(faults: &[CellFault], sim: &Sim, deaths: &[ReleaseDeath; 2]) {
    for fault in faults {
        let at = Instant::from_start(fault.at);
        let kind = match fault.kind {
            CellFaultKind::ReleaseDies(line) => {
                *deaths[line.index()]
                    .lock()
                    .unwrap_or_else(PoisonError::into_inner) = Some(at);
                continue;
            }
            CellFaultKind::RobotFault(line) => FaultKind::Robot(RobotId::new(line, Role::ChipIt)),
            CellFaultKind::FeederEmpty(feeder) => FaultKind::FeederEmpty(feeder),
            CellFaultKind::PalletJam(line) => FaultKind::Jam(line, Station::Load),
        };
        sim.inject(Fault { at, kind });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn faults_parse_with_defaults_and_units() {
        assert_eq!(
            "robot:B@15m".parse(),
            Ok(CellFault {
                kind: CellFaultKind::RobotFault(Line::B),
                at: Duration::from_secs(900)
            })
        );
        assert_eq!(
            "release@600".parse(),
            Ok(CellFault {
                kind: CellFaultKind::ReleaseDies(Line::A),
                at: Duration::from_secs(600)
            })
        );
        assert_eq!(
            "feeder:2@1h".parse::<CellFault>().map(|f| f.kind),
            Ok(CellFaultKind::FeederEmpty(FeederId(2)))
        );
    }

    #[test]
    fn a_bad_fault_says_what_was_wrong() {
        let error = "robot:C@10".parse::<CellFault>().unwrap_err().to_string();
        assert!(
            error.starts_with("--fault \"robot:C@10\": the line must be A or B"),
            "{error}"
        );
        let error = "meteor@10".parse::<CellFault>().unwrap_err().to_string();
        assert!(error.contains("unknown kind"), "{error}");
        let error = "jam@soon".parse::<CellFault>().unwrap_err().to_string();
        assert!(error.contains("the time is not a number"), "{error}");
        let error = "jam@1e300h".parse::<CellFault>().unwrap_err().to_string();
        assert!(error.contains("within a year"), "{error}");
    }
}
