//! The table's rows, as defined: what each measures (a case over its baseline, a tail's
//! p99.9 over another's, or an idle module's memory), and the target it is held to.

/// A measured case: criterion's id, what the table calls it, and what one iteration's time is
/// divided by before it is compared (the tasks of a waitfor round, for a time per task).
#[derive(Clone)]
pub(super) struct Case {
    pub(super) id: String,
    pub(super) name: &'static str,
    pub(super) per: f64,
}

/// A case timed per iteration as it is.
fn case(id: impl Into<String>, name: &'static str) -> Case {
    Case {
        id: id.into(),
        name,
        per: 1.0,
    }
}

/// What a row compares its case with.
pub(super) enum Baseline {
    One(Case),
    /// The faster of two, in each run: the nearest equivalents that differ in placement.
    Faster(Case, Case),
    /// The slower of the same two, reported beside the faster.
    Slower(Case, Case),
}

/// What a row measures.
pub(super) enum Measure {
    /// The case's time over the baseline's.
    Ratio(Case, Baseline),
    /// p99.9 of single round trips (the tail files of `benches/rendezvous.rs`), over the
    /// baseline's p99.9.
    TailRatio(&'static str, &'static str),
    /// Resident KiB per idle module from `idle_modules`, beside a tokio task's.
    IdleKib,
}

/// A row of the table, as defined.
pub(super) struct Def {
    pub(super) key: String,
    pub(super) case: String,
    pub(super) baseline: String,
    pub(super) target: &'static str,
    pub(super) measure: Measure,
    /// What the figures are per: " a hop", " a task"; empty for a round trip.
    pub(super) unit: &'static str,
}

/// Every row of the table, in its order.
pub(super) fn rows() -> Vec<Def> {
    let mut rows = Vec::new();
    let mut row = |key: String,
                   case: &str,
                   baseline: &str,
                   target: &'static str,
                   measure: Measure,
                   unit: &'static str| {
        rows.push(Def {
            key,
            case: case.into(),
            baseline: baseline.into(),
            target,
            measure,
            unit,
        })
    };
    let one = |id: &str, name| Baseline::One(case(id, name));

    row(
        "ctx/one_processor".into(),
        "`ctx` round trip, both modules on one processor",
        "raw `End` round trip, both ends on one processor",
        "≤ 1.15",
        Measure::Ratio(
            case("ctx_same_thread/ctx", "ctx"),
            one("ctx_same_thread/raw_end", "raw End"),
        ),
        "",
    );
    row(
        "ctx/two_workers".into(),
        "`ctx` round trip, each module a task of a two-worker runtime",
        "raw `End` round trip, placed the same",
        "≤ 1.15",
        Measure::Ratio(
            case("ctx_multi_thread/ctx", "ctx"),
            one("ctx_multi_thread/raw_end", "raw End"),
        ),
        "",
    );

    let imrs_ring_1 = || case("ring_1000/imrs/1_threads", "imrs");
    row(
        "ring/tokio/1".into(),
        "ring of 1,000 modules, 1 thread, time per hop",
        "1,000 tokio tasks + mpsc + oneshot, 1 thread",
        "≤ 1.0",
        Measure::Ratio(imrs_ring_1(), one("ring_1000/tokio/1_threads", "tokio")),
        " a hop",
    );
    row(
        "ring/kameo/1".into(),
        "ring of 1,000 modules, 1 thread",
        "1,000 kameo actors, each hop an `ask`, 1 thread",
        "< 1",
        Measure::Ratio(imrs_ring_1(), one("ring_1000/kameo/1_threads", "kameo")),
        " a hop",
    );
    row(
        "ring/ractor/1".into(),
        "ring of 1,000 modules, 1 thread",
        "1,000 ractor actors, each hop a `call!`, 1 thread",
        "< 1",
        Measure::Ratio(imrs_ring_1(), one("ring_1000/ractor/1_threads", "ractor")),
        " a hop",
    );
    let cores = std::thread::available_parallelism().map_or(2, usize::from);
    let mut threads = vec![2, cores];
    threads.dedup();
    for n in threads.into_iter().filter(|&n| n > 1) {
        let id = |who: &str| format!("ring_1000/{who}/{n}_threads");
        row(
            format!("ring/tokio/{n}"),
            &format!("ring of 1,000 modules, {n} threads"),
            &format!("1,000 tokio tasks + mpsc + oneshot, {n} threads"),
            if n == 2 { "≤ 1.2" } else { "–" },
            Measure::Ratio(case(id("imrs"), "imrs"), one(&id("tokio"), "tokio")),
            " a hop",
        );
    }

    for (size, bytes, main) in [("8B", "8 B", true), ("1KiB", "1 KiB", false)] {
        let same = |who: &str| format!("rendezvous_same_thread/{who}/{size}");
        let target = |t: &'static str| if main { t } else { "–" };
        let two_tasks = case(same("imrs_two_tasks"), "imrs");
        row(
            format!("same_thread/two_tasks/tokio/{size}"),
            &format!("same-thread {bytes}, each end a task (current-thread runtime)"),
            "tokio mpsc + oneshot ask, each end a task, same runtime",
            target("≤ 0.7"),
            Measure::Ratio(two_tasks.clone(), one(&same("tokio_two_tasks"), "tokio")),
            "",
        );
        let processor = case(same("imrs_one_processor"), "imrs");
        let (join, local) = (
            case(same("tokio_join_one_task"), "tokio `join!` in one task"),
            case(
                same("tokio_local_set"),
                "tokio, two tasks of one `LocalSet`",
            ),
        );
        row(
            format!("same_thread/one_processor/nearest/{size}"),
            &format!("same-thread {bytes}, both ends jobs of one processor"),
            "the faster of its nearest tokio equivalents",
            target("≤ 0.5"),
            Measure::Ratio(
                processor.clone(),
                Baseline::Faster(join.clone(), local.clone()),
            ),
            "",
        );
        if main {
            row(
                format!("same_thread/one_processor/other/{size}"),
                &format!("same-thread {bytes}, both ends jobs of one processor"),
                "the slower of them",
                "–",
                Measure::Ratio(processor, Baseline::Slower(join, local)),
                "",
            );
        }
        row(
            format!("same_thread/two_tasks/kameo/{size}"),
            &format!("same-thread {bytes}, each end a task"),
            "kameo `ask`, actor and asker placed the same",
            target("< 1"),
            Measure::Ratio(two_tasks.clone(), one(&same("kameo_ask"), "kameo")),
            "",
        );
        row(
            format!("same_thread/two_tasks/ractor/{size}"),
            &format!("same-thread {bytes}, each end a task"),
            "ractor `call!`, actor and caller placed the same",
            target("< 1"),
            Measure::Ratio(two_tasks, one(&same("ractor_call"), "ractor")),
            "",
        );
        if main {
            row(
                format!("same_thread/prioritized/{size}"),
                &format!("same-thread {bytes} on one processor, priorities on"),
                "priorities off",
                "≤ 1.05",
                Measure::Ratio(
                    case(same("imrs_one_processor_prioritized"), "on"),
                    one(&same("imrs_one_processor"), "off"),
                ),
                "",
            );
        }
    }

    row(
        "idle".into(),
        "idle module, 10,000 modules waiting in `ctx.receive`: KiB resident each",
        "a tokio task waiting on an mpsc receiver",
        "≤ 1.5 KiB",
        Measure::IdleKib,
        "",
    );
    row(
        "filter/processor".into(),
        "bounded-buffer filter, a job on one processor with its peers",
        "tokio bounded mpsc, one task",
        "≤ 2",
        Measure::Ratio(
            case("filter/bounded_buffer_on_processor", "filter"),
            one("filter/tokio_mpsc", "mpsc"),
        ),
        "",
    );
    row(
        "filter/task".into(),
        "bounded-buffer filter, a task of its own",
        "tokio bounded mpsc, one task",
        "–",
        Measure::Ratio(
            case("filter/bounded_buffer", "filter"),
            one("filter/tokio_mpsc", "mpsc"),
        ),
        "",
    );
    let per_task = |id: &str, n: f64| Case {
        id: id.into(),
        name: "",
        per: n,
    };
    for (n, id, tokio_id) in [
        (64.0, "waitfor/64", "waitfor/tokio_barrier/64"),
        (256.0, "waitfor/256", "waitfor/tokio_barrier/256"),
    ] {
        row(
            format!("waitfor/{n}"),
            &format!("waitfor, per task, n = {n}"),
            "waitfor, per task, n = 2",
            "≤ 1.05",
            Measure::Ratio(per_task(id, n), Baseline::One(per_task("waitfor/2", 2.0))),
            " a task",
        );
        row(
            format!("waitfor/tokio/{n}"),
            &format!("tokio `Barrier`, per task, n = {n}"),
            "tokio `Barrier`, per task, n = 2",
            "–",
            Measure::Ratio(
                per_task(tokio_id, n),
                Baseline::One(per_task("waitfor/tokio_barrier/2", 2.0)),
            ),
            " a task",
        );
    }
    row(
        "query/idle".into(),
        "query into a response handler, responder idle",
        "rendezvous, both ends on one processor",
        "≤ 1.5",
        Measure::Ratio(
            case("query/responder_idle", "query"),
            one("query/same_thread_rendezvous", "rendezvous"),
        ),
        "",
    );
    row(
        "query/busy".into(),
        "query, responder in a lower-ranked section",
        "rendezvous, both ends on one processor",
        "–",
        Measure::Ratio(
            case("query/responder_in_lower_section", "query"),
            one("query/same_thread_rendezvous", "rendezvous"),
        ),
        "",
    );
    row(
        "select".into(),
        "`select` over 8 ports, all ready",
        "one ready",
        "–",
        Measure::Ratio(
            case("select/8_ports_all_ready", "all"),
            one("select/8_ports_one_ready", "one"),
        ),
        "",
    );

    for (size, bytes, main) in [("8B", "8 B", true), ("1KiB", "1 KiB", false)] {
        let cold = |who: &str| format!("rendezvous_cross_thread_cold/{who}/{size}");
        let placed = "placed the same (a current-thread runtime on each thread)";
        let imrs = case(cold("imrs"), "imrs");
        row(
            format!("cold/tokio/{size}"),
            &format!("cross-thread cold {bytes} (server on a thread of its own)"),
            &format!("tokio mpsc + oneshot ask, {placed}"),
            if main { "≤ 0.8" } else { "–" },
            Measure::Ratio(imrs.clone(), one(&cold("tokio_ask"), "tokio")),
            "",
        );
        if main {
            row(
                format!("cold/tokio/p999/{size}"),
                &format!("cross-thread cold {bytes}, p99.9"),
                "tokio ask's p99.9",
                "≤ 1",
                Measure::TailRatio(
                    "rendezvous_cross_thread_cold_imrs_8B",
                    "rendezvous_cross_thread_cold_tokio_ask_8B",
                ),
                "",
            );
            row(
                format!("cold/kameo/{size}"),
                &format!("cross-thread cold {bytes}"),
                &format!("kameo `ask`, {placed}"),
                "–",
                Measure::Ratio(imrs.clone(), one(&cold("kameo_ask"), "kameo")),
                "",
            );
            row(
                format!("cold/ractor/{size}"),
                &format!("cross-thread cold {bytes}"),
                &format!("ractor `call!`, {placed}"),
                "–",
                Measure::Ratio(imrs, one(&cold("ractor_call"), "ractor")),
                "",
            );
            row(
                format!("cold/crossbeam/{size}"),
                &format!("crossbeam ping-pong {bytes}, two threads"),
                "tokio mpsc + oneshot ask across threads",
                "–",
                Measure::Ratio(
                    case(cold("crossbeam_ping_pong"), "crossbeam"),
                    one(&cold("tokio_ask"), "tokio"),
                ),
                "",
            );
        }
    }
    for (size, bytes, target) in [("8B", "8 B", "≤ 1.2"), ("1KiB", "1 KiB", "≤ 1.2")] {
        let tight = |who: &str| format!("rendezvous_tight/{who}/{size}");
        row(
            format!("tight/payload/{size}"),
            &format!("TIGHT {bytes}"),
            &format!("two threads spinning on a cache line that carries the {bytes}"),
            target,
            Measure::Ratio(
                case(tight("imrs"), "imrs"),
                one(&tight("atomic_spin_ping_pong_payload"), "spin"),
            ),
            "",
        );
    }
    row(
        "tight/plain/8B".into(),
        "TIGHT 8 B",
        "two threads spinning on one atomic, no message",
        "–",
        Measure::Ratio(
            case("rendezvous_tight/imrs/8B", "imrs"),
            one("rendezvous_tight/atomic_spin_ping_pong/8B", "spin"),
        ),
        "",
    );
    rows
}
