//! Which of the seed's mechanisms buys what, measured by rapier over the same arrivals:
//! arms that cannot stop at once intrude into zones unless the pipeline's offset covers
//! their stopping distance (an offset too small is the negative control), and their links
//! meet outside the zones unless the coordinator checks their way against where the
//! others told it they are.

use table_cell::{Ablation, Assignment, Coordination, ablation};

const SEEDS: std::ops::RangeInclusive<u64> = 1..=10;

fn rows() -> Ablation {
    ablation(
        &[
            (Coordination::ZonesOnly, Assignment::Programs),
            (Coordination::PipelineOffset(1), Assignment::Programs),
            (Coordination::Pipeline, Assignment::Programs),
            (Coordination::Full, Assignment::Programs),
        ],
        SEEDS,
        0.2,
    )
    .expect("the cell runs")
}

#[test]
fn each_mechanism_removes_what_rapier_measures_without_it() {
    let table = rows();
    println!("{table}");
    let [zones_only, offset_one, pipeline, full] = &table.rows[..] else {
        panic!("four rows: {table}");
    };
    for row in &table.rows {
        assert_eq!(row.reports.len(), 10, "{table}");
        assert_eq!(row.failures(), 0, "{table}");
        // Not safe because idle: every row made units and slept arms at the borders.
        assert!(row.per_hour() > 100.0, "{table}");
        assert!(row.slept() > 100, "{table}");
    }
    // A zone asked for at its border: refused, the arm brakes into it.
    assert!(zones_only.zone_conflicts() > 0, "{table}");
    // The negative control: an offset of one point, short of every arm's stopping
    // distance, and rapier measures intrusions again.
    assert!(offset_one.zone_conflicts() > 0, "{table}");
    // The offset computed from each arm's stopping distance: no intrusion, in any seed.
    assert_eq!(pipeline.zone_conflicts(), 0, "{table}");
    for report in &pipeline.reports {
        assert!(report.measured.zone_conflicts.is_empty(), "{report}");
    }
    // Zones alone do not keep the links apart outside them.
    assert!(pipeline.collisions() > 0, "{table}");
    // The coordinator's check of the way ahead and its alternative trajectory do.
    assert!(full.is_safe(), "{table}");
    assert!(full.closest().is_some_and(|c| c > 0.0), "{table}");
    assert!(full.reports.iter().all(|r| r.stats.detours > 0), "{table}");
}
