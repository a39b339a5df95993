//! A line's figures as they cross to the world, a JSON line, and the world's folding of them
//! into its own.

use super::*;

/// A line's figures: what its modules' events counted, its chip robot's waits, its GATE's
/// cycle times, and how late its timer woke at worst.
pub(super) fn figures(
    tally: &Tally,
    waits: &ZoneWaits,
    history: &CycleTimeHistory,
    lateness: Duration,
) -> Value {
    let alarm_kinds: Vec<Value> = tally
        .alarm_kinds
        .iter()
        .map(|(kind, count)| json!([kind.map(AlarmKind::label), count]))
        .collect();
    json!({
        "timeouts": tally.timeouts,
        "restarts": tally.restarts,
        "alarms": tally.alarms,
        "alarm_kinds": alarm_kinds,
        "deadlocks": tally.deadlocks,
        "last_deadlock": tally.last_deadlock,
        "deadlock_lost": tally.deadlock_lost,
        "waits": [waits.asks, waits.refused, waits.waited],
        "cycle_time": {
            "first": history.first,
            "now": history.now,
            "range": history.range.map(|(low, high)| [low, high]),
            "changes": history.changes,
            "recent": history.recent.iter().map(|(at, value)| [*at, *value]).collect::<Vec<_>>(),
        },
        "lateness_us": u64::try_from(lateness.as_micros()).unwrap_or(u64::MAX),
    })
}

/// Folds a line's figures into the world's; `None` if they do not read.
pub(super) fn absorb(
    tally: &mut Tally,
    waits: &mut ZoneWaits,
    history: &mut CycleTimeHistory,
    lateness: &mut Duration,
    figures: &Value,
) -> Option<()> {
    let count = |value: &Value| value.as_u64().and_then(|n| u32::try_from(n).ok());
    let float = |value: &Value| {
        if value.is_null() {
            Some(None)
        } else {
            value.as_f64().map(Some)
        }
    };
    for (port, n) in figures["timeouts"].as_object()? {
        *tally.timeouts.entry(port.clone()).or_insert(0) += count(n)?;
    }
    tally.restarts += count(&figures["restarts"])?;
    tally.alarms += count(&figures["alarms"])?;
    for pair in figures["alarm_kinds"].as_array()? {
        let kind = match &pair[0] {
            Value::Null => None,
            label => {
                let label = label.as_str()?;
                Some(
                    AlarmKind::ALL
                        .into_iter()
                        .find(|kind| kind.label() == label)?,
                )
            }
        };
        *tally.alarm_kinds.entry(kind).or_insert(0) += count(&pair[1])?;
    }
    tally.deadlocks += count(&figures["deadlocks"])?;
    if let Some(last) = float(&figures["last_deadlock"])? {
        tally.last_deadlock = Some(tally.last_deadlock.map_or(last, |other| other.max(last)));
    }
    tally.deadlock_lost += figures["deadlock_lost"].as_f64()?;
    // A line's runs, folded in order: the waits of each add up.
    let asked = &figures["waits"];
    waits.asks += count(&asked[0])?;
    waits.refused += count(&asked[1])?;
    waits.waited += asked[2].as_f64()?;
    let cycle = &figures["cycle_time"];
    let pair = |value: &Value| Some((value[0].as_f64()?, value[1].as_f64()?));
    let run = CycleTimeHistory {
        first: float(&cycle["first"])?,
        now: float(&cycle["now"])?,
        range: match &cycle["range"] {
            Value::Null => None,
            range => Some(pair(range)?),
        },
        changes: count(&cycle["changes"])?,
        recent: cycle["recent"]
            .as_array()?
            .iter()
            .map(pair)
            .collect::<Option<_>>()?,
    };
    history.follow(run);
    *lateness = (*lateness).max(Duration::from_micros(figures["lateness_us"].as_u64()?));
    Some(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_lines_figures_cross_as_json_and_fold_into_the_worlds() {
        let mut line = Tally::default();
        line.timeouts.insert("LET_1_GO".into(), 2);
        line.restarts = 1;
        line.alarms = 3;
        line.alarm_kinds.insert(Some(AlarmKind::EmptyFeeder), 2);
        line.alarm_kinds.insert(None, 1);
        line.deadlocks = 1;
        line.last_deadlock = Some(120.5);
        line.deadlock_lost = 4.25;
        let waits = ZoneWaits {
            asks: 10,
            refused: 1,
            waited: 12.5,
        };
        let history = CycleTimeHistory {
            first: Some(10.0),
            now: Some(9.0),
            range: Some((8.0, 10.0)),
            changes: 2,
            recent: vec![(100.0, 9.5), (200.0, 9.0)],
        };
        // Sent over a pipe as text, and read back.
        let text = figures(&line, &waits, &history, Duration::from_micros(2500)).to_string();
        let read: Value = serde_json::from_str(&text).unwrap();
        let mut world = Tally::default();
        world.timeouts.insert("LET_1_GO".into(), 1);
        world.alarms = 1;
        let (mut got_waits, mut got_history, mut got_lateness) = Default::default();
        absorb(
            &mut world,
            &mut got_waits,
            &mut got_history,
            &mut got_lateness,
            &read,
        )
        .unwrap();
        assert_eq!(world.timeouts["LET_1_GO"], 3);
        assert_eq!(world.restarts, 1);
        assert_eq!(world.alarms, 4);
        assert_eq!(world.alarm_kinds[&Some(AlarmKind::EmptyFeeder)], 2);
        assert_eq!(world.alarm_kinds[&None], 1);
        assert_eq!((world.deadlocks, world.last_deadlock), (1, Some(120.5)));
        assert_eq!(world.deadlock_lost, 4.25);
        assert_eq!(got_waits, waits);
        assert_eq!(got_history, history);
        assert_eq!(got_lateness, Duration::from_micros(2500));
    }

    #[test]
    fn figures_that_do_not_read_are_refused() {
        let read = |figures: &Value| {
            let (mut waits, mut history, mut lateness) = Default::default();
            absorb(
                &mut Tally::default(),
                &mut waits,
                &mut history,
                &mut lateness,
                figures,
            )
        };
        let good = figures(
            &Tally::default(),
            &ZoneWaits::default(),
            &CycleTimeHistory::default(),
            Duration::ZERO,
        );
        assert_eq!(read(&good), Some(()));
        for broken in [
            "restarts",
            "waits",
            "cycle_time",
            "alarm_kinds",
            "lateness_us",
        ] {
            let mut figures = good.clone();
            figures[broken] = json!("garbage");
            assert_eq!(read(&figures), None, "{broken}");
        }
        let mut unknown_kind = good;
        unknown_kind["alarm_kinds"] = json!([["no such kind", 1]]);
        assert_eq!(read(&unknown_kind), None);
    }
}
