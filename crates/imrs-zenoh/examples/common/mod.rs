//! What the benchmarks against raw zenoh share: the message both sides move (a CDR `u64`),
//! the run's length, the table of their percentiles, and hosts as network namespaces.

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

/// A network namespace joined to this one by a veth link, removed when dropped.
pub(crate) struct Namespace {
    /// Its name, for `ip netns exec`.
    pub(crate) name: String,
    /// Its address on the link.
    #[allow(dead_code)] // each example reads the end of the link it needs
    pub(crate) inside: String,
    /// This namespace's address on the link.
    #[allow(dead_code)]
    pub(crate) outside: String,
}

impl Namespace {
    /// The `k`th namespace of this process (root is needed).
    pub(crate) fn make(k: u32) -> Result<Self, Box<dyn std::error::Error>> {
        let id = std::process::id() % 100_000;
        let name = format!("imrsb-{id}-{k}");
        let (outside_dev, inside_dev) = (format!("imrsbo{id}{k}"), format!("imrsbi{id}{k}"));
        let subnet = format!("10.{}.{}", 200 + k, id % 250);
        let ns = Self {
            name: name.clone(),
            inside: format!("{subnet}.2"),
            outside: format!("{subnet}.1"),
        };
        let steps: [&[&str]; 7] = [
            &["netns", "add", &name],
            &[
                "link",
                "add",
                &outside_dev,
                "type",
                "veth",
                "peer",
                "name",
                &inside_dev,
                "netns",
                &name,
            ],
            &[
                "addr",
                "add",
                &format!("{subnet}.1/30"),
                "dev",
                &outside_dev,
            ],
            &["link", "set", &outside_dev, "up"],
            &[
                "-n",
                &name,
                "addr",
                "add",
                &format!("{subnet}.2/30"),
                "dev",
                &inside_dev,
            ],
            &["-n", &name, "link", "set", &inside_dev, "up"],
            &["-n", &name, "link", "set", "lo", "up"],
        ];
        for step in steps {
            let status = std::process::Command::new("ip").args(step).status()?;
            if !status.success() {
                return Err(format!("ip {} failed (root is needed)", step.join(" ")).into());
            }
        }
        Ok(ns)
    }

    /// A command that runs `program` inside the namespace.
    pub(crate) fn command(&self, program: &std::path::Path) -> tokio::process::Command {
        let mut command = tokio::process::Command::new("ip");
        command.args(["netns", "exec", &self.name]).arg(program);
        command
    }
}

impl Drop for Namespace {
    fn drop(&mut self) {
        let _ = std::process::Command::new("ip")
            .args(["netns", "del", &self.name])
            .status();
    }
}
