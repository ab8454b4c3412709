//! Replay frames from JSON Lines through the processor and write JSON Lines
//! results: `replay [INPUT.jsonl] [OUTPUT.jsonl]` (default stdin/stdout).
//! A bad line (bad JSON, a bad field, text after the object, bytes that
//! are not UTF-8) gives an error line (and a message on stderr) naming the
//! line and the field; processing goes on with the next line. Exit code 0
//! if every line was accepted, 1 if some were rejected, 2 if reading or
//! writing failed.

use std::io::{BufRead, BufReader, Write};

use host_tests::jsonl::replay;
use roadstereo::{Config, Processor};

/// Capacity of the replay processor: up to 1024 points per boundary.
const N: usize = 1024;
/// Up to 4 boundaries per frame.
const B: usize = 4;

fn main() -> std::process::ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let input: Box<dyn BufRead> = match args.first().map(String::as_str) {
        None | Some("-") => Box::new(BufReader::new(std::io::stdin())),
        Some(path) => match std::fs::File::open(path) {
            Ok(f) => Box::new(BufReader::new(f)),
            Err(e) => {
                eprintln!("replay: cannot open {path}: {e}");
                return std::process::ExitCode::from(2);
            }
        },
    };
    let mut output: Box<dyn Write> = match args.get(1) {
        None => Box::new(std::io::stdout().lock()),
        Some(path) => match std::fs::File::create(path) {
            Ok(f) => Box::new(std::io::BufWriter::new(f)),
            Err(e) => {
                eprintln!("replay: cannot create {path}: {e}");
                return std::process::ExitCode::from(2);
            }
        },
    };
    let mut p = Box::new(Processor::<N, B>::new(Config::default()));
    let done = match replay(&mut p, input, &mut output, |e| eprintln!("replay: {e}")) {
        Ok(done) => done,
        Err(e) => {
            eprintln!("replay: {e}");
            let _ = output.flush();
            return std::process::ExitCode::from(2);
        }
    };
    let errors = done.errors;
    let _ = output.flush();
    if errors > 0 {
        eprintln!("replay: {errors} line(s) rejected");
        std::process::ExitCode::from(1)
    } else {
        std::process::ExitCode::SUCCESS
    }
}
