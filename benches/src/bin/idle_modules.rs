//! Scale: how much memory an idle module costs, and how long modules take to start.
//!
//! Starts `N` modules (10 000 unless told), each owning a port and waiting in `ctx.receive`
//! on it, on one current-thread runtime; prints the resident memory they added per module,
//! measured from the process's own page count (`/proc/self/statm`), and the time to start
//! them all. Beside it, in a process of its own so that neither reuses the other's freed
//! memory, the same count of tokio tasks each waiting on an mpsc receiver. Each figure is
//! also saved under `<criterion>/idle/` (criterion's output directory), where `ratio_table`
//! reads it.
//!
//! ```text
//! cargo run --release -p imrs-benches --bin idle_modules [N]
//! ```

use std::process::Command;
use std::time::Duration;

use imrs_benches::{criterion_dir, current_thread, idle_modules, idle_tokio_tasks, resident_bytes};

fn main() {
    let mut args = std::env::args().skip(1);
    let count: usize = args.next().and_then(|n| n.parse().ok()).unwrap_or(10_000);
    let Some(before) = resident_bytes() else {
        eprintln!("no /proc/self/statm here: resident memory cannot be read");
        std::process::exit(1);
    };
    let runtime = current_thread();
    match args.next().as_deref() {
        Some("imrs") => {
            let (modules, started) = runtime.block_on(idle_modules(count));
            report("imrs", "modules", count, before, started);
            drop(modules);
        }
        Some("tokio") => {
            let (tasks, started) = runtime.block_on(idle_tokio_tasks(count));
            report("tokio", "tasks", count, before, started);
            drop(tasks);
        }
        _ => {
            let me = std::env::current_exe().expect("the program knows its path");
            for what in ["imrs", "tokio"] {
                let status = Command::new(&me)
                    .args([count.to_string(), what.to_owned()])
                    .status()
                    .expect("the program runs itself");
                if !status.success() {
                    std::process::exit(1);
                }
            }
        }
    }
}

/// Prints what `count` idle `who` `things` added to the resident memory, and saves it as
/// `<criterion>/idle/<who>.txt`: KiB each, the count, and the milliseconds to start them.
fn report(who: &str, things: &str, count: usize, before: usize, started: Duration) {
    let after = resident_bytes().unwrap_or(before);
    let per = after.saturating_sub(before) as f64 / count as f64 / 1024.0;
    let millis = started.as_secs_f64() * 1e3;
    println!(
        "{count} idle {who} {things}: {per:.2} KiB resident each, started in {millis:.1} ms \
         ({:.2} us each)",
        started.as_secs_f64() * 1e6 / count as f64
    );
    let dir = criterion_dir().join("idle");
    let saved = std::fs::create_dir_all(&dir).and_then(|()| {
        std::fs::write(
            dir.join(format!("{who}.txt")),
            format!("{per:.3} {count} {millis:.1}\n"),
        )
    });
    if let Err(error) = saved {
        eprintln!("cannot save the figure for ratio_table: {error}");
    }
}
