//! A timeline picture of a window of a run: one row per module showing which section it was
//! in and when its background code or handlers waited on a peer, one row per robot showing
//! when rapier saw it inside the feeder zone, and marks for deadlocks and timeouts.
//!
//! A module's other tasks (device drivers such as a freeze relay's, which wait on their own
//! module by design) get a row of their own, `MODULE/TASK`, when they wait: on the module's
//! row they would hide the waits that matter, such as the two chip robots querying each
//! other in the deadlock of Shin 1985's note 6.
//!
//! Folded from the event streams as they come, keeping only what falls inside the window,
//! so that its memory does not grow with the run's length. Drawn with plotters' SVG backend.

use std::collections::HashMap;
use std::path::Path;
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::time::Duration;

use imrs_core::{Cell, EventKind};
use imrs_scene::{World, ZoneChange};
use plotters::prelude::*;

use crate::error::RecordError;

/// What a stretch of a row shows.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum SpanKind {
    /// The module was in this named section.
    Section(String),
    /// The module waited on a peer through this port (a send or a query).
    Blocked(String),
    /// The robot was inside the feeder zone.
    InZone,
    /// Two or more robots were inside the feeder zone together.
    ZoneShared,
}

/// A stretch of time on a row, in seconds of the cell's clock.
#[derive(Debug, Clone, PartialEq)]
pub struct Span {
    /// Where it starts.
    pub from: f64,
    /// Where it ends.
    pub to: f64,
    /// What it shows.
    pub kind: SpanKind,
}

/// A row of the picture.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// A module's name, or `zone: ROBOT`, or `feeder zone`.
    pub name: String,
    /// Its stretches, in the order they ended.
    pub spans: Vec<Span>,
}

/// A moment marked on the picture.
#[derive(Debug, Clone, PartialEq)]
pub struct Mark {
    /// When, in seconds of the cell's clock.
    pub at: f64,
    /// The row it belongs to; `None` for the whole picture.
    pub row: Option<usize>,
    /// What happened.
    pub kind: MarkKind,
    /// Its label.
    pub label: String,
}

/// What a mark marks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MarkKind {
    /// A deadlock was reported.
    Deadlock,
    /// A timeout was raised.
    Timeout,
}

/// The timeline of a window of a run.
#[derive(Debug, Clone)]
pub struct Timeline {
    fold: Arc<Mutex<Fold>>,
}

#[derive(Debug)]
struct Fold {
    from: f64,
    to: f64,
    last: f64,
    rows: Vec<Row>,
    row_of: HashMap<String, usize>,
    /// Sections entered and not yet left: (row, task, section) to when.
    open: HashMap<(usize, &'static str, &'static str), f64>,
    /// Robots inside the zone: robot to when it entered.
    inside: HashMap<String, f64>,
    shared_since: Option<f64>,
    marks: Vec<Mark>,
}

impl Timeline {
    /// A timeline of the window from `from` to `to` of the cell's clock.
    pub fn new(from: Duration, to: Duration) -> Self {
        let (from, to) = (from.as_secs_f64(), to.as_secs_f64().max(from.as_secs_f64()));
        Self {
            fold: Arc::new(Mutex::new(Fold {
                from,
                to,
                last: from,
                rows: Vec::new(),
                row_of: HashMap::new(),
                open: HashMap::new(),
                inside: HashMap::new(),
                shared_since: None,
                marks: Vec::new(),
            })),
        }
    }

    /// Folds every event of `cell` from now on; turns [`Cell::observe`] on, for the waits.
    pub fn record_cell(&self, cell: &Cell) {
        cell.observe(true);
        let fold = Arc::clone(&self.fold);
        cell.events().subscribe(move |event| {
            let at = event.at.since_start().as_secs_f64();
            let mut fold = lock(&fold);
            fold.last = fold.last.max(at);
            let row = fold.row(event.module.as_str());
            // Names are interned: the fold keys on them without copying a string per event.
            let task: &'static str = event.task.as_ref().map_or("", |task| task.as_str());
            match &event.kind {
                EventKind::SectionEntered { section } => {
                    fold.open.insert((row, task, section.as_str()), at);
                }
                EventKind::SectionLeft { section } => {
                    if let Some(since) = fold.open.remove(&(row, task, section.as_str())) {
                        fold.span(row, since, at, SpanKind::Section(section.to_string()));
                    }
                }
                EventKind::Sent {
                    port,
                    observed: Some(observed),
                }
                | EventKind::Queried {
                    port,
                    observed: Some(observed),
                } => {
                    let since = at - observed.waited.as_secs_f64();
                    fold.blocked(row, event.module.as_str(), task, (since, at), port.as_str());
                }
                EventKind::PortError {
                    port,
                    primitive,
                    observed: Some(observed),
                    ..
                } if primitive.awaits_a_peer() => {
                    let since = at - observed.waited.as_secs_f64();
                    fold.blocked(row, event.module.as_str(), task, (since, at), port.as_str());
                }
                EventKind::ExceptionRaised { exception }
                    if exception.as_str().ends_with(".TIMEOUT") =>
                {
                    fold.mark(at, Some(row), MarkKind::Timeout, exception.to_string());
                }
                EventKind::Deadlock { cycle } => {
                    let label = cycle
                        .iter()
                        .map(|(module, _)| module.to_string())
                        .collect::<Vec<_>>()
                        .join(" -> ");
                    fold.mark(at, None, MarkKind::Deadlock, format!("deadlock {label}"));
                }
                _ => {}
            }
        });
    }

    /// Folds every fact a simulated world measures from now on: who is inside its shared
    /// (feeder) zone.
    pub fn record_sim(&self, world: &dyn World) {
        let fold = Arc::clone(&self.fold);
        world.facts(Box::new(move |fact| {
            let at = fact.at.as_secs_f64();
            let mut fold = lock(&fold);
            fold.last = fold.last.max(at);
            match &fact.zone {
                Some(ZoneChange::Entered(robot)) => {
                    let robot = robot.clone();
                    fold.row(&format!("zone: {robot}"));
                    fold.row("feeder zone");
                    fold.inside.insert(robot, at);
                    if fold.inside.len() >= 2 && fold.shared_since.is_none() {
                        fold.shared_since = Some(at);
                    }
                }
                Some(ZoneChange::Left(robot)) => {
                    let robot = robot.clone();
                    if let Some(since) = fold.inside.remove(&robot) {
                        let row = fold.row(&format!("zone: {robot}"));
                        fold.span(row, since, at, SpanKind::InZone);
                    }
                    if fold.inside.len() < 2
                        && let Some(since) = fold.shared_since.take()
                    {
                        let row = fold.row("feeder zone");
                        fold.span(row, since, at, SpanKind::ZoneShared);
                    }
                }
                None => {}
            }
        }));
    }

    /// The rows as they would be drawn now: stretches still open end at the last event seen.
    pub fn rows(&self) -> Vec<Row> {
        lock(&self.fold).closed().0
    }

    /// The marks as they would be drawn now.
    pub fn marks(&self) -> Vec<Mark> {
        lock(&self.fold).marks.clone()
    }

    /// Draws the timeline as an SVG picture at `path`.
    pub fn render_svg(&self, path: impl AsRef<Path>) -> Result<(), RecordError> {
        let path = path.as_ref();
        let (rows, marks, window) = {
            let fold = lock(&self.fold);
            let (rows, _) = fold.closed();
            (
                rows,
                fold.marks.clone(),
                (fold.from, fold.to.min(fold.last)),
            )
        };
        draw(path, &rows, &marks, window).map_err(|error| RecordError::Draw {
            path: path.to_path_buf(),
            error,
        })
    }
}

impl Fold {
    fn row(&mut self, name: &str) -> usize {
        if let Some(&row) = self.row_of.get(name) {
            return row;
        }
        self.rows.push(Row {
            name: name.to_string(),
            spans: Vec::new(),
        });
        self.row_of.insert(name.to_string(), self.rows.len() - 1);
        self.rows.len() - 1
    }

    /// The row of a task's waits: the module's own for its background code (the task named
    /// after the module) and its handlers (named `PORT.HANDLER`), else `MODULE/TASK`.
    fn task_row(&mut self, module_row: usize, module: &str, task: &str) -> usize {
        if task.is_empty() || task == module || task.contains('.') {
            module_row
        } else {
            self.row(&format!("{module}/{task}"))
        }
    }

    /// A wait on a peer from `since` to `until`, on its task's row: made only if the wait
    /// reaches into the window, so that a run's length adds no rows.
    fn blocked(
        &mut self,
        module_row: usize,
        module: &str,
        task: &str,
        (since, until): (f64, f64),
        port: &str,
    ) {
        if since.max(self.from) < until.min(self.to) {
            let row = self.task_row(module_row, module, task);
            self.span(row, since, until, SpanKind::Blocked(port.to_string()));
        }
    }

    /// Keeps the part of a stretch that lies inside the window.
    fn span(&mut self, row: usize, from: f64, to: f64, kind: SpanKind) {
        let (from, to) = (from.max(self.from), to.min(self.to));
        if from < to {
            self.rows[row].spans.push(Span { from, to, kind });
        }
    }

    fn mark(&mut self, at: f64, row: Option<usize>, kind: MarkKind, label: String) {
        if (self.from..=self.to).contains(&at) {
            self.marks.push(Mark {
                at,
                row,
                kind,
                label,
            });
        }
    }

    /// The rows with every stretch still open ended at the last event seen.
    fn closed(&self) -> (Vec<Row>, f64) {
        let end = self.last.min(self.to);
        let mut rows = self.rows.clone();
        let clip = |from: f64| (from.max(self.from), end);
        for ((row, _, section), &since) in &self.open {
            let (from, to) = clip(since);
            if from < to {
                rows[*row].spans.push(Span {
                    from,
                    to,
                    kind: SpanKind::Section(section.to_string()),
                });
            }
        }
        for (robot, &since) in &self.inside {
            let (from, to) = clip(since);
            if let (Some(&row), true) = (self.row_of.get(&format!("zone: {robot}")), from < to) {
                rows[row].spans.push(Span {
                    from,
                    to,
                    kind: SpanKind::InZone,
                });
            }
        }
        if let (Some(since), Some(&row)) = (self.shared_since, self.row_of.get("feeder zone")) {
            let (from, to) = clip(since);
            if from < to {
                rows[row].spans.push(Span {
                    from,
                    to,
                    kind: SpanKind::ZoneShared,
                });
            }
        }
        // Each module's task rows under it, the zone's rows last.
        let place = |row: &Row| {
            let zone = row.name.starts_with("zone: ") || row.name == "feeder zone";
            let module = row
                .name
                .split_once('/')
                .map_or(row.name.as_str(), |(m, _)| m);
            let first = self.row_of.get(module).copied().unwrap_or(usize::MAX);
            (zone, first, row.name.contains('/'), self.row_of[&row.name])
        };
        rows.sort_by_key(|row| place(row));
        (rows, end)
    }
}

/// The colour of a section: the chip cell's named ones fixed, any other from its name.
fn section_colour(section: &str) -> RGBColor {
    match section {
        "GRASP" => RGBColor(66, 133, 244),
        "INSERT" => RGBColor(52, 168, 83),
        "BACK_OFF" => RGBColor(171, 71, 188),
        other => {
            let hash = other
                .bytes()
                .fold(17u32, |h, b| h.wrapping_mul(31).wrapping_add(u32::from(b)));
            let channel = |shift: u32| 80 + ((hash >> shift) & 0x7f) as u8;
            RGBColor(channel(0), channel(8), channel(16))
        }
    }
}

const BLOCKED: RGBColor = RGBColor(239, 108, 0);
const IN_ZONE: RGBColor = RGBColor(255, 193, 7);
const DEADLOCK: RGBColor = RGBColor(211, 47, 47);
const ROW_HEIGHT: u32 = 26;
const LABEL_WIDTH: u32 = 190;

type Drawn = Result<(), String>;

fn draw(path: &Path, rows: &[Row], marks: &[Mark], (from, to): (f64, f64)) -> Drawn {
    let to = if to > from { to } else { from + 1.0 };
    let n = rows.len().max(1);
    let height = 130 + ROW_HEIGHT * n as u32;
    let root = SVGBackend::new(path, (1400, height)).into_drawing_area();
    let err = |e: &dyn std::fmt::Display| e.to_string();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let mut chart = ChartBuilder::on(&root)
        .margin(10)
        .margin_top(84)
        .x_label_area_size(30)
        .y_label_area_size(LABEL_WIDTH)
        .build_cartesian_2d(from..to, 0.0..n as f64)
        .map_err(|e| err(&e))?;
    chart
        .configure_mesh()
        .disable_y_mesh()
        .y_labels(0)
        .x_desc("seconds")
        .draw()
        .map_err(|e| err(&e))?;
    // Rows run top down: row i sits between n - i - 1 and n - i.
    let top = |i: usize| (n - i) as f64;
    for (i, row) in rows.iter().enumerate() {
        let y = top(i);
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(from, y - 0.9), (to, y - 0.1)],
                RGBColor(238, 238, 238).filled(),
            )))
            .map_err(|e| err(&e))?;
        let bars = row.spans.iter().map(|span| {
            let (low, high, colour) = match &span.kind {
                SpanKind::Section(section) => (y - 0.9, y - 0.1, section_colour(section)),
                SpanKind::Blocked(_) => (y - 0.75, y - 0.25, BLOCKED),
                SpanKind::InZone => (y - 0.9, y - 0.1, IN_ZONE),
                SpanKind::ZoneShared => (y - 0.9, y - 0.1, DEADLOCK),
            };
            Rectangle::new([(span.from, low), (span.to, high)], colour.filled())
        });
        chart.draw_series(bars).map_err(|e| err(&e))?;
        let (x, y) = chart.backend_coord(&(from, y - 0.5));
        root.draw(&Text::new(
            row.name.clone(),
            (x - LABEL_WIDTH as i32 + 8, y - 7),
            ("sans-serif", 13),
        ))
        .map_err(|e| err(&e))?;
    }
    // Deadlock labels alternate between two heights, so that close ones stay readable.
    let mut labelled = 0;
    for mark in marks {
        match mark.kind {
            MarkKind::Deadlock => {
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        vec![(mark.at, 0.0), (mark.at, n as f64)],
                        DEADLOCK.stroke_width(2),
                    )))
                    .map_err(|e| err(&e))?;
                let (x, y) = chart.backend_coord(&(mark.at, n as f64));
                root.draw(&Text::new(
                    mark.label.clone(),
                    (x + 4, y - 14 - 13 * (labelled % 2)),
                    ("sans-serif", 12).into_font().color(&DEADLOCK),
                ))
                .map_err(|e| err(&e))?;
                labelled += 1;
            }
            MarkKind::Timeout => {
                let y = top(mark.row.unwrap_or(0)) - 0.1;
                chart
                    .draw_series(std::iter::once(TriangleMarker::new(
                        (mark.at, y),
                        5,
                        DEADLOCK.filled(),
                    )))
                    .map_err(|e| err(&e))?;
            }
        }
    }
    legend(&root, rows).map_err(|e| err(&e))?;
    root.draw(&Text::new(
        format!("who did what, {from:.0} s to {to:.0} s of the cell's clock"),
        (10, 32),
        ("sans-serif", 16),
    ))
    .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))
}

/// The key, across the top: each section drawn, then the other marks.
fn legend<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    rows: &[Row],
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let mut sections: Vec<&str> = Vec::new();
    for span in rows.iter().flat_map(|row| &row.spans) {
        if let SpanKind::Section(section) = &span.kind
            && !sections.contains(&section.as_str())
        {
            sections.push(section);
        }
    }
    let mut keys: Vec<(String, RGBColor)> =
        vec![("background / handler".into(), RGBColor(238, 238, 238))];
    keys.extend(sections.iter().map(|s| (s.to_string(), section_colour(s))));
    keys.push(("waiting on a peer".into(), BLOCKED));
    keys.push(("in the feeder zone".into(), IN_ZONE));
    keys.push(("zone shared / deadlock".into(), DEADLOCK));
    let mut x = 10;
    for (name, colour) in keys {
        root.draw(&Rectangle::new([(x, 8), (x + 14, 22)], colour.filled()))?;
        root.draw(&Text::new(name.clone(), (x + 18, 9), ("sans-serif", 12)))?;
        x += 30 + 7 * name.len() as i32;
    }
    Ok(())
}

fn lock<T>(mutex: &Mutex<T>) -> MutexGuard<'_, T> {
    // A fold is one call that leaves the rows whole.
    mutex.lock().unwrap_or_else(PoisonError::into_inner)
}
