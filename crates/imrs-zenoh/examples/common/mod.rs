//! What the benchmarks against raw zenoh share: the message both sides move (a CDR `u64`),
//! the run's length, and the table of their percentiles.

use std::time::Duration;

/// `n` in CDR, as the raw queryables read and write it by hand.
pub(crate) fn cdr(n: u64) -> Vec<u8> {
    let mut bytes = vec![0, 1, 0, 0];
    bytes.extend_from_slice(&n.to_le_bytes());
    bytes
}

/// The `u64` a CDR payload holds (0 if it holds none).
pub(crate) fn read(bytes: &[u8]) -> u64 {
    bytes
        .get(4..12)
        .and_then(|b| b.try_into().ok())
        .map_or(0, u64::from_le_bytes)
}

/// `--rounds N` from `args`, or `default`.
pub(crate) fn rounds(args: &[String], default: usize) -> Result<usize, std::num::ParseIntError> {
    args.iter()
        .position(|a| a == "--rounds")
        .and_then(|i| args.get(i + 1))
        .map_or(Ok(default), |n| n.parse())
}

/// Prints p50 and p99 of IMRS's case and the raw one, and their ratios, as a Markdown table.
pub(crate) fn table(imrs_case: &str, imrs: &mut [Duration], raw_case: &str, raw: &mut [Duration]) {
    let (a50, a99) = (percentile(imrs, 0.50), percentile(imrs, 0.99));
    let (b50, b99) = (percentile(raw, 0.50), percentile(raw, 0.99));
    println!("| case | p50 | p99 |");
    println!("|---|---:|---:|");
    println!("| {imrs_case} | {a50:.1?} | {a99:.1?} |");
    println!("| {raw_case} | {b50:.1?} | {b99:.1?} |");
    println!(
        "| ratio | {:.2}× | {:.2}× |",
        a50.as_secs_f64() / b50.as_secs_f64(),
        a99.as_secs_f64() / b99.as_secs_f64()
    );
}

fn percentile(samples: &mut [Duration], q: f64) -> Duration {
    samples.sort_unstable();
    samples[((samples.len() - 1) as f64 * q).round() as usize]
}

/// A command that runs `program` inside `netns`, or here.
pub(crate) fn command_in(
    netns: Option<&imrs_zenoh::netns::Netns>,
    program: &std::path::Path,
) -> tokio::process::Command {
    match netns {
        Some(netns) => netns.command(program).into(),
        None => tokio::process::Command::new(program),
    }
}
