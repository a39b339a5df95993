//! A line's process that died during a run across processes: when, how long the line was
//! down, and what it cost.

use std::fmt;

use imrs_sim::Line;

/// One death of a line's process (or the cut of its host), and the line's return.
#[derive(Debug, Clone, PartialEq)]
pub struct Outage {
    /// The line.
    pub line: Line,
    /// Whether its host was cut off (its process, alive behind the cut, was stopped), rather
    /// than its process dead.
    pub cut_off: bool,
    /// When its process was seen dead, or its host cut off, in simulated seconds.
    pub died: f64,
    /// When the next run said it was ready, in simulated seconds; `None` if the cell's run
    /// ended first.
    pub back: Option<f64>,
    /// The run of the line's process started in its place (the first is run 0).
    pub run: u32,
    /// The pallets its stations held, taken off as scrap.
    pub scrapped: u32,
}

impl Outage {
    /// How long the line was down, in simulated seconds, if it came back.
    pub fn lasted(&self) -> Option<f64> {
        self.back.map(|back| back - self.died)
    }
}

impl fmt::Display for Outage {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let line = match self.line {
            Line::A => "A",
            Line::B => "B",
        };
        let what = if self.cut_off {
            "host was cut off"
        } else {
            "process died"
        };
        write!(
            f,
            "line {line}'s {what} at {:.1} s; started again (run {}), ",
            self.died, self.run
        )?;
        match self.lasted() {
            Some(lasted) => write!(f, "back {lasted:.1} s later")?,
            None => write!(f, "not back before the end")?,
        }
        let pallets = if self.scrapped == 1 { "" } else { "s" };
        write!(f, "; {} pallet{pallets} it held scrapped", self.scrapped)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_outage_says_when_how_long_and_what_it_cost() {
        let outage = Outage {
            line: Line::A,
            cut_off: false,
            died: 120.25,
            back: Some(131.5),
            run: 1,
            scrapped: 2,
        };
        assert_eq!(
            outage.to_string(),
            "line A's process died at 120.2 s; started again (run 1), back 11.2 s later; \
             2 pallets it held scrapped"
        );
        let unfinished = Outage {
            back: None,
            scrapped: 1,
            ..outage
        };
        assert!(
            unfinished
                .to_string()
                .ends_with("not back before the end; 1 pallet it held scrapped")
        );
        let cut = Outage {
            cut_off: true,
            ..outage
        };
        assert!(
            cut.to_string()
                .starts_with("line A's host was cut off at 120.2 s")
        );
    }
}
