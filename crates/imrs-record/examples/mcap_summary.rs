//! Sums up an MCAP recording: its channels, their schemas and message counts, and the time
//! it spans. A truncated or corrupt file is refused with a message naming it (status 1).
//!
//! ```text
//! cargo run --example mcap_summary -- cell.mcap
//! ```

use std::process::ExitCode;

fn main() -> ExitCode {
    let mut args = std::env::args_os().skip(1);
    let (Some(path), None) = (args.next(), args.next()) else {
        eprintln!("usage: mcap_summary FILE.mcap");
        return ExitCode::from(2);
    };
    match imrs_record::read_summary(&path) {
        Ok(summary) => {
            print!("{summary}");
            ExitCode::SUCCESS
        }
        Err(error) => {
            eprintln!("{error}");
            ExitCode::FAILURE
        }
    }
}
