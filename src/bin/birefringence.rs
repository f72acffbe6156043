//! `birefringence`: a JSON calculator over the core.
//!
//! ```text
//! birefringence <subcommand> [--batch] [FILE]
//! ```
//! Reads one JSON object from FILE (or standard input) and writes one JSON object; with
//! `--batch`, reads JSON lines and writes one output line per input line (an invalid line gives
//! an `{"error": ...}` line and the others still run). Exit code 0 if every case succeeded, 1 if
//! any gave an error, 2 for a usage error.

use birefringent::calc;
use std::io::{BufRead, Read, Write};

const USAGE: &str = "usage: birefringence <subcommand> [--batch] [FILE]
subcommands: interface, slab, stack
Reads one JSON object (or JSON lines with --batch) from FILE or standard input.
See docs/calculator.md for the fields.";

fn main() {
    std::process::exit(run());
}

fn run() -> i32 {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.iter().any(|a| a == "-h" || a == "--help") {
        println!("{USAGE}");
        return 0;
    }
    let batch = args.iter().any(|a| a == "--batch");
    let rest: Vec<&String> = args.iter().filter(|a| *a != "--batch").collect();
    let (sub, file) = match rest.as_slice() {
        [sub] => (sub.as_str(), None),
        [sub, file] => (sub.as_str(), Some(file.as_str())),
        _ => {
            eprintln!("{USAGE}");
            return 2;
        }
    };
    if !calc::SUBCOMMANDS.contains(&sub) {
        eprintln!("unknown subcommand '{sub}'\n{USAGE}");
        return 2;
    }
    let reader: Box<dyn Read> = match file {
        None => Box::new(std::io::stdin()),
        Some(path) => match std::fs::File::open(path) {
            Ok(f) => Box::new(f),
            Err(e) => {
                eprintln!("cannot open {path}: {e}");
                return 2;
            }
        },
    };
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    if batch {
        let mut all_ok = true;
        for line in std::io::BufReader::new(reader).lines() {
            let line = match line {
                Ok(l) => l,
                Err(e) => {
                    eprintln!("read error: {e}");
                    return 2;
                }
            };
            if line.trim().is_empty() {
                continue;
            }
            let (v, ok) = calc::run_text(sub, &line);
            all_ok &= ok;
            if writeln!(out, "{v}").is_err() {
                return 2;
            }
        }
        i32::from(!all_ok)
    } else {
        let mut text = String::new();
        if let Err(e) = std::io::BufReader::new(reader).read_to_string(&mut text) {
            eprintln!("read error: {e}");
            return 2;
        }
        let (v, ok) = calc::run_text(sub, &text);
        let pretty = serde_json::to_string_pretty(&v).unwrap_or_else(|_| v.to_string());
        if writeln!(out, "{pretty}").is_err() {
            return 2;
        }
        i32::from(!ok)
    }
}
