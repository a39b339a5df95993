//! The cross-thread cold round trip, run several times in one process: IMRS against tokio
//! mpsc + oneshot, each with the receiver on a current-thread runtime in a thread of its own
//! (parked between messages) and the asker on a current-thread runtime of the main thread,
//! each run timing both, one after the other. Prints every run's ratio and both p99.9 tails,
//! then the median and the spread: on a shared machine one run says little.
//!
//! ```text
//! cargo run --release -p imrs-benches --bin cross_thread_runs [RUNS] [ROUND_TRIPS]
//! ```

use imrs_benches::Tail;
use imrs_benches::rendezvous::{imrs_cross_thread, tokio_ask_cross_thread};
use imrs_ports::ProcessType;

fn main() {
    let mut args = std::env::args().skip(1);
    let runs: usize = args.next().and_then(|n| n.parse().ok()).unwrap_or(5);
    let round_trips: u64 = args.next().and_then(|n| n.parse().ok()).unwrap_or(20_000);
    let mut ratios = Vec::with_capacity(runs);
    let mut tails = Vec::with_capacity(runs);
    println!("run  imrs mean  tokio mean  ratio  imrs p99.9  tokio p99.9");
    for run in 1..=runs {
        let (mut imrs, mut tokio) = (
            Tail::with_capacity(round_trips as usize),
            Tail::with_capacity(round_trips as usize),
        );
        let imrs_time = imrs_cross_thread::<8>(round_trips, ProcessType::Loose, Some(&mut imrs));
        let tokio_time = tokio_ask_cross_thread::<8>(round_trips, Some(&mut tokio));
        let (imrs_mean, tokio_mean) = (
            imrs_time.as_secs_f64() * 1e9 / round_trips as f64,
            tokio_time.as_secs_f64() * 1e9 / round_trips as f64,
        );
        let ratio = imrs_mean / tokio_mean;
        let (imrs_tail, tokio_tail) = (imrs.percentile(99.9), tokio.percentile(99.9));
        println!(
            "{run:>3}  {imrs_mean:>7.0} ns  {tokio_mean:>8.0} ns  {ratio:>5.2}  {:>7.1} us  {:>8.1} us",
            imrs_tail.as_secs_f64() * 1e6,
            tokio_tail.as_secs_f64() * 1e6
        );
        ratios.push(ratio);
        tails.push((imrs_tail, tokio_tail));
    }
    ratios.sort_by(f64::total_cmp);
    let median = ratios[ratios.len() / 2];
    let (low, high) = (ratios[0], ratios[ratios.len() - 1]);
    println!(
        "ratio: median {median:.2} over {runs} runs, spread {low:.2} to {high:.2} (target <= 0.8)"
    );
    let mut imrs_tails: Vec<_> = tails.iter().map(|(imrs, _)| *imrs).collect();
    let mut tokio_tails: Vec<_> = tails.iter().map(|(_, tokio)| *tokio).collect();
    imrs_tails.sort();
    tokio_tails.sort();
    println!(
        "p99.9: median imrs {:.1} us, tokio {:.1} us (target: imrs <= tokio)",
        imrs_tails[runs / 2].as_secs_f64() * 1e6,
        tokio_tails[runs / 2].as_secs_f64() * 1e6
    );
}
