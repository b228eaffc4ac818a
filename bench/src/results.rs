//! `--results DIR`: the run as a Markdown page (`DIR/latest.md`) with the machine, the exact
//! command and the whole table, and its JSON beside it (`DIR/latest.json`), so that a
//! committed run says what it was measured on and how to measure it again.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::BenchError;
use crate::report::Report;

/// A line into the page being built: writing to a `String` cannot fail.
macro_rules! out {
    ($($arg:tt)*) => {
        writeln!($($arg)*).expect("writing to a String cannot fail")
    };
}

/// The page's file name in the results directory.
pub const PAGE: &str = "latest.md";
/// The JSON's file name in the results directory.
pub const JSON: &str = "latest.json";

/// The page and JSON paths in `dir`.
pub fn paths(dir: &Path) -> (PathBuf, PathBuf) {
    (dir.join(PAGE), dir.join(JSON))
}

/// `args` as one shell command line: each argument quoted when it holds anything but
/// letters, digits and `-_./=,:+@%`.
pub fn command_line(args: impl IntoIterator<Item = String>) -> String {
    args.into_iter()
        .map(|a| {
            let plain = !a.is_empty()
                && a.chars()
                    .all(|c| c.is_ascii_alphanumeric() || "-_./=,:+@%".contains(c));
            if plain {
                a
            } else {
                format!("'{}'", a.replace('\'', r"'\''"))
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// The environment variables a run reads (where the bridges, the C and Python clients and
/// the domain's files come from, Zenoh's threads): set ones go before the command.
pub const ENV: &[&str] = &[
    "LIMBER_RUNTIME_DIR",
    "LIMBER_BIN",
    "LIMBER_PYTHON",
    "LIMBER_LIB_DIR",
    "LIMBER_SPIN_US",
    "LIMBER_PRIORITY",
    "CC",
    "ZENOH_RUNTIME",
];

/// This process's command line, after the variables of [`ENV`] that are set (`VAR=value`).
pub fn invocation() -> String {
    let env = ENV
        .iter()
        .filter_map(|k| std::env::var(k).ok().map(|v| format!("{k}={v}")));
    command_line(env.chain(std::env::args()))
}

/// A Unix time as `YYYY-MM-DD HH:MM:SS UTC` (civil from days, proleptic Gregorian).
fn utc(unix_s: u64) -> String {
    let (days, secs) = (unix_s / 86_400, unix_s % 86_400);
    // Howard Hinnant's days-to-civil algorithm.
    let z = days as i64 + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1_460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02} {:02}:{:02}:{:02} UTC",
        secs / 3_600,
        secs / 60 % 60,
        secs % 60
    )
}

/// The Markdown page of `report`, run as `command`.
pub fn page(report: &Report, command: &str) -> String {
    let m = &report.machine;
    let mut t = String::new();
    out!(t, "# limber bench: the latest run\n");
    out!(
        t,
        "Written by `limber bench --results DIR`; every ratio and goal below compares \
         series of this one run.\n"
    );
    out!(t, "| | |\n|---|---|");
    out!(t, "| when | {} |", utc(m.started_unix_s));
    out!(t, "| CPU | {} |", m.cpu);
    out!(t, "| cores | {} |", m.cores);
    out!(t, "| kernel | {} |", m.kernel);
    out!(
        t,
        "| load average at the start | {:.2} {:.2} {:.2} |",
        m.load_avg[0],
        m.load_avg[1],
        m.load_avg[2]
    );
    out!(t, "| build | {} |", m.build);
    out!(t, "| pinning | {} |", m.pinning);
    out!(t, "| counts | {} |", m.mode);
    let failed = report.failed();
    if failed > 0 {
        out!(t, "| scenarios failed | {failed} |");
    }
    out!(t, "\nThe command:\n");
    out!(
        t,
        "<!-- not run by tests: * | a benchmark run, minutes long, recorded as it ran -->"
    );
    out!(t, "```sh\n{command}\n```\n");
    let missed: Vec<String> = report
        .ratios
        .iter()
        .filter(|r| r.met == Some(false))
        .map(|r| format!("{} = {:.2}{}", r.label, r.value, r.floor_note()))
        .chain(
            report
                .time_goals
                .iter()
                .filter(|g| !g.met)
                .map(|g| g.label.clone()),
        )
        .chain(
            report
                .cpu
                .iter()
                .filter(|c| c.met() == Some(false))
                .map(|c| format!("{} {} {}: {:.2} %", c.mode, c.load, c.process, c.percent)),
        )
        .collect();
    if missed.is_empty() {
        out!(t, "Every goal of this run was met.\n");
    } else {
        out!(t, "Goals **not met** in this run:\n");
        for m in &missed {
            out!(t, "* {m}");
        }
        out!(t);
    }
    out!(t, "The table, ratios, goals and CPU costs as printed:\n");
    out!(t, "```text{}```", report.table());
    t
}

/// Writes `DIR/latest.md` and `DIR/latest.json`.
pub fn write(dir: &Path, report: &Report, command: &str) -> Result<(), BenchError> {
    let (md, json) = paths(dir);
    std::fs::write(&md, page(report, command))
        .map_err(|e| BenchError::io(md.display().to_string(), e))?;
    report.write_json(&json)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_command_line_quotes_what_a_shell_would_split() {
        let args = [
            "limber",
            "bench",
            "--only",
            "state,bridge",
            "--results",
            "a b",
            "it's",
        ];
        assert_eq!(
            command_line(args.iter().map(|s| s.to_string())),
            r"limber bench --only state,bridge --results 'a b' 'it'\''s'"
        );
    }

    #[test]
    fn unix_times_read_as_utc_dates() {
        assert_eq!(utc(0), "1970-01-01 00:00:00 UTC");
        assert_eq!(utc(951_782_400), "2000-02-29 00:00:00 UTC");
        assert_eq!(utc(1_795_740_727), "2026-11-27 00:52:07 UTC");
    }
}
