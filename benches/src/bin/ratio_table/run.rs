//! One run's rows: measured from criterion's estimates (and the tail and idle files beside
//! them), printed, and saved to `<criterion>/ratios.tsv`, one line a row.

use std::path::Path;

use imrs_benches::criterion_dir;

use super::emit;
use super::rows::{Baseline, Case, Def, Measure, rows};

/// The median of a case, in nanoseconds, from `<criterion>/<case>/new/estimates.json`.
fn median(root: &Path, case: &str) -> Option<f64> {
    let text = std::fs::read_to_string(root.join(case).join("new/estimates.json")).ok()?;
    let after = &text[text.find("\"median\"")?..];
    let after = &after[after.find("\"point_estimate\":")? + "\"point_estimate\":".len()..];
    let end = after.find([',', '}'])?;
    after[..end].trim().parse().ok()
}

/// A time in nanoseconds, in the unit that suits it.
fn show(nanos: f64) -> String {
    if nanos >= 1e6 {
        format!("{:.2} ms", nanos / 1e6)
    } else if nanos >= 1e3 {
        format!("{:.2} µs", nanos / 1e3)
    } else {
        format!("{nanos:.0} ns")
    }
}

/// A row of one run, as saved in `ratios.tsv`: the value is a ratio, or KiB for the idle row.
#[derive(Clone)]
pub(super) struct Measured {
    pub(super) key: String,
    pub(super) case: String,
    pub(super) baseline: String,
    pub(super) target: String,
    pub(super) value: Option<f64>,
    pub(super) kib: bool,
    pub(super) figures: String,
}

impl Measured {
    fn to_line(&self) -> String {
        let value = self.value.map_or("-".into(), |v| format!("{v:.4}"));
        let unit = if self.kib { "KiB" } else { "ratio" };
        [
            self.key.as_str(),
            &self.case,
            &self.baseline,
            self.target.as_str(),
            &value,
            unit,
            &self.figures,
        ]
        .join("\t")
    }

    pub(super) fn from_line(line: &str) -> Option<Self> {
        let fields: Vec<&str> = line.split('\t').collect();
        let [key, case, baseline, target, value, unit, figures] = fields[..] else {
            return None;
        };
        Some(Self {
            key: key.into(),
            case: case.into(),
            baseline: baseline.into(),
            target: target.into(),
            value: value.parse().ok(),
            kib: unit == "KiB",
            figures: figures.into(),
        })
    }

    pub(super) fn show_value(&self, value: f64) -> String {
        if self.kib {
            format!("{value:.2} KiB")
        } else {
            format!("{value:.2}")
        }
    }
}

/// One row of this run, measured from what `root` holds.
fn measure(root: &Path, def: &Def) -> Measured {
    let mut measured = Measured {
        key: def.key.clone(),
        case: def.case.clone(),
        baseline: def.baseline.clone(),
        target: def.target.into(),
        value: None,
        kib: false,
        figures: "-".into(),
    };
    let timed = |case: &Case| median(root, &case.id).map(|nanos| nanos / case.per);
    match &def.measure {
        Measure::Ratio(case, baseline) => {
            let base = match baseline {
                Baseline::One(base) => timed(base).map(|nanos| (base, nanos)),
                Baseline::Faster(a, b) | Baseline::Slower(a, b) => match (timed(a), timed(b)) {
                    (Some(x), Some(y)) => {
                        let faster = x <= y;
                        let pick_a = faster == matches!(baseline, Baseline::Faster(..));
                        Some(if pick_a { (a, x) } else { (b, y) })
                    }
                    _ => None,
                },
            };
            if matches!(baseline, Baseline::Faster(..) | Baseline::Slower(..))
                && let Some((base, _)) = base
            {
                measured.baseline = format!("{}: {}", def.baseline, base.name);
            }
            if let (Some(a), Some((_, b))) = (timed(case), base)
                && b > 0.0
            {
                measured.value = Some(a / b);
                measured.figures = format!("{}{} vs {}", show(a), def.unit, show(b));
            }
        }
        Measure::TailRatio(case, baseline) => {
            let p999 = |name: &str| -> Option<f64> {
                let text =
                    std::fs::read_to_string(root.join("tail").join(format!("{name}.txt"))).ok()?;
                text.split_whitespace().nth(2)?.parse().ok()
            };
            if let (Some(a), Some(b)) = (p999(case), p999(baseline))
                && b > 0.0
            {
                measured.value = Some(a / b);
                measured.figures = format!("{} vs {}", show(a), show(b));
            }
        }
        Measure::IdleKib => {
            measured.kib = true;
            let figure = |who: &str| -> Option<(f64, String)> {
                let text =
                    std::fs::read_to_string(root.join("idle").join(format!("{who}.txt"))).ok()?;
                let mut fields = text.split_whitespace();
                let kib = fields.next()?.parse().ok()?;
                let (count, millis) = (fields.next()?, fields.next()?);
                Some((kib, format!("{count} started in {millis} ms")))
            };
            if let Some((kib, started)) = figure("imrs") {
                measured.value = Some(kib);
                measured.figures = format!("{kib:.2} KiB ({started})");
                if let Some((tokio, _)) = figure("tokio") {
                    measured.figures.push_str(&format!(" vs {tokio:.2} KiB"));
                }
            }
        }
    }
    measured
}

/// This run's table, from criterion's estimates; saves its rows to `<criterion>/ratios.tsv`.
pub(super) fn one_run() {
    let mut out = String::new();
    let root = criterion_dir();
    if !root.exists() {
        eprintln!(
            "no estimates under {}: run `cargo bench` first",
            root.display()
        );
        std::process::exit(1);
    }
    let mut saved = String::new();
    say!(
        out,
        "{:<72} {:>8}  target",
        "case (baseline below)",
        "ratio"
    );
    for def in rows() {
        let row = measure(&root, &def);
        saved.push_str(&row.to_line());
        saved.push('\n');
        let value = row.value.map_or("-".into(), |v| row.show_value(v));
        say!(out, "{:<72} {value:>8}  {}", row.case, row.target);
        say!(out, "  vs {}: {}", row.baseline, row.figures);
    }
    if let Err(error) = std::fs::write(root.join("ratios.tsv"), saved) {
        eprintln!("cannot save this run's ratios: {error}");
    }
    if let Some(minute) = median(&root, "sim_speed/busy_cell_minute") {
        say!(
            out,
            "sim_speed: {:.0} simulated seconds per wall second (busy two-line cell)",
            60.0 / (minute / 1e9)
        );
    }
    say!(out);
    say!(
        out,
        "tail latency of single round trips (p50 / p99 / p99.9):"
    );
    let mut tails: Vec<_> = std::fs::read_dir(root.join("tail"))
        .map(|dir| {
            dir.filter_map(Result::ok)
                .map(|entry| entry.path())
                .collect()
        })
        .unwrap_or_default();
    tails.sort();
    for path in tails {
        let text = std::fs::read_to_string(&path).unwrap_or_default();
        let values: Vec<Option<f64>> = text.split_whitespace().map(|v| v.parse().ok()).collect();
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        if let [Some(p50), Some(p99), Some(p999)] = values[..] {
            say!(
                out,
                "  {name:<56} {} / {} / {}",
                show(p50),
                show(p99),
                show(p999)
            );
        }
    }
    emit(&out);
}
