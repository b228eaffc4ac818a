//! `limber actarray DEVICE traj FILE|-`: a joint trajectory from a CSV file an engineer
//! writes by hand, and `limber actarray DEVICE scale F`.
//!
//! The file: `#` starts a comment, blank lines are skipped; the first line is the header,
//! naming each column: `t` (the point's time from the start, s; exactly once), `jN` (the
//! position of actarray joint N; at least one), and optionally `vN` (its velocity) and `aN`
//! (its acceleration) for every joint that has a `jN`. Then one line per point:
//!
//! ```text
//! t,j0,j1
//! 1.0,0.2,-0.1
//! 2.0,0.4,-0.2
//! ```
//!
//! Positions only are followed on straight lines, with velocities on cubics, with
//! accelerations too on quintics.

use std::io::Read;

use clap::Args;
use limber_interfaces::actarray::{JointTrajectory, MAX_TRAJ_POINTS};
use limber_services::TrajectorySendError;
use limber_services::prelude::*;

use crate::out::outln;
use crate::{CliError, exit};

/// Arguments of `traj`.
#[derive(Debug, Args)]
pub struct TrajArgs {
    /// The CSV file of the points (`-`: standard input): a header `t,j0,j1,...` with
    /// optional `v0,...` (velocities) and `a0,...` (accelerations) columns, one line per
    /// point.
    file: String,
    /// Path tolerance of every joint (rad or m; 0: not enforced): a joint further than
    /// this from where it should be ends the trajectory, holding.
    #[arg(long, default_value_t = 0.0, value_name = "TOL")]
    path_tolerance: f64,
    /// Goal tolerance of every joint (rad or m; 0: not enforced).
    #[arg(long, default_value_t = 0.0, value_name = "TOL")]
    goal_tolerance: f64,
    /// Seconds after the last point within which the joints must be within the goal
    /// tolerance (0: the driver's default).
    #[arg(long, default_value_t = 0.0, value_name = "S")]
    goal_time: f64,
    /// Speed scaling sent first (0 pauses, 1 nominal); the device keeps it.
    #[arg(long, value_name = "F")]
    scale: Option<f64>,
}

fn bad(line: usize, what: impl core::fmt::Display) -> CliError {
    CliError::new(exit::USAGE, format!("trajectory file, line {line}: {what}"))
}

/// One column of the header.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Column {
    Time,
    Position(u16),
    Velocity(u16),
    Acceleration(u16),
}

fn column(name: &str, line: usize) -> Result<Column, CliError> {
    let name = name.trim();
    if name == "t" {
        return Ok(Column::Time);
    }
    let (kind, index) = name.split_at(name.len().min(1));
    let j: u16 = index
        .parse()
        .map_err(|_| bad(line, format_args!("column {name:?} is not t, jN, vN or aN")))?;
    match kind {
        "j" => Ok(Column::Position(j)),
        "v" => Ok(Column::Velocity(j)),
        "a" => Ok(Column::Acceleration(j)),
        _ => Err(bad(
            line,
            format_args!("column {name:?} is not t, jN, vN or aN"),
        )),
    }
}

/// Reads a trajectory from the CSV text (see the module's documentation).
pub fn parse(text: &str) -> Result<Box<JointTrajectory>, CliError> {
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.split('#').next().unwrap_or("").trim()))
        .filter(|(_, l)| !l.is_empty());
    let (hline, header) = lines
        .next()
        .ok_or_else(|| bad(1, "empty: no header line (t,j0,j1,...)"))?;
    let cols = header
        .split(',')
        .map(|c| column(c, hline))
        .collect::<Result<Vec<_>, _>>()?;
    let joints: Vec<u16> = cols
        .iter()
        .filter_map(|c| match c {
            Column::Position(j) => Some(*j),
            _ => None,
        })
        .collect();
    if cols.iter().filter(|c| **c == Column::Time).count() != 1 {
        return Err(bad(hline, "the header needs one column t"));
    }
    let index_of = |want: fn(u16) -> Column| -> Result<Option<Vec<usize>>, CliError> {
        let found: Vec<Option<usize>> = joints
            .iter()
            .map(|&j| cols.iter().position(|c| *c == want(j)))
            .collect();
        let given = found.iter().filter(|f| f.is_some()).count();
        let extra = cols
            .iter()
            .filter(|c| {
                matches!(
                    (want(0), c),
                    (Column::Velocity(_), Column::Velocity(_))
                        | (Column::Acceleration(_), Column::Acceleration(_))
                )
            })
            .count();
        if given == 0 && extra == 0 {
            Ok(None)
        } else if given == joints.len() && extra == joints.len() {
            Ok(Some(found.into_iter().flatten().collect()))
        } else {
            Err(bad(
                hline,
                "velocity (vN) and acceleration (aN) columns must be given for every joint jN or none",
            ))
        }
    };
    let vel = index_of(Column::Velocity)?;
    let acc = index_of(Column::Acceleration)?;
    let pos: Vec<usize> = joints
        .iter()
        .filter_map(|&j| cols.iter().position(|c| *c == Column::Position(j)))
        .collect();
    let t_col = cols.iter().position(|c| *c == Column::Time).unwrap_or(0);
    let mut traj =
        JointTrajectory::new(&joints).map_err(|e| bad(hline, format_args!("header: {e}")))?;
    let mut row = vec![0.0; cols.len()];
    let pick = |row: &[f64], idx: &[usize]| idx.iter().map(|&i| row[i]).collect::<Vec<f64>>();
    for (n, (line, text)) in lines.enumerate() {
        if n >= MAX_TRAJ_POINTS {
            return Err(bad(
                line,
                format_args!("more than {MAX_TRAJ_POINTS} points (split it into several)"),
            ));
        }
        let fields: Vec<&str> = text.split(',').collect();
        if fields.len() != cols.len() {
            return Err(bad(
                line,
                format_args!(
                    "{} values, the header has {} columns",
                    fields.len(),
                    cols.len()
                ),
            ));
        }
        for (v, f) in row.iter_mut().zip(&fields) {
            *v = f
                .trim()
                .parse()
                .map_err(|_| bad(line, format_args!("{:?} is not a number", f.trim())))?;
        }
        let p = pick(&row, &pos);
        let v = vel.as_ref().map(|i| pick(&row, i));
        let a = acc.as_ref().map(|i| pick(&row, i));
        traj.push(row[t_col], &p, v.as_deref(), a.as_deref())
            .map_err(|e| bad(line, e))?;
    }
    Ok(traj)
}

fn read(file: &str) -> Result<String, CliError> {
    let mut text = String::new();
    let r = if file == "-" {
        std::io::stdin().read_to_string(&mut text).map(|_| ())
    } else {
        std::fs::File::open(file).and_then(|mut f| f.read_to_string(&mut text).map(|_| ()))
    };
    r.map_err(|e| CliError::new(exit::USAGE, format!("cannot read {file}: {e}")))?;
    Ok(text)
}

/// Builds the trajectory of `traj` (file and tolerances), sends the scaling first if
/// asked, then the trajectory.
pub fn send(
    c: &mut Client<ActArray>,
    a: &TrajArgs,
    timeout: std::time::Duration,
) -> Result<Ticket, CliError> {
    let mut t = parse(&read(&a.file)?)?;
    let n = t.joints().len();
    let usage = |e: TrajectoryError| CliError::new(exit::USAGE, format!("invalid trajectory: {e}"));
    t.set_path_tolerance(&vec![a.path_tolerance; n])
        .map_err(usage)?;
    t.set_goal_tolerance(&vec![a.goal_tolerance; n])
        .map_err(usage)?;
    t.set_goal_time_tolerance(a.goal_time).map_err(usage)?;
    if let Some(f) = a.scale {
        let ticket = c
            .set_trajectory_scale(f)
            .map_err(crate::device::command_err)?;
        let s = c
            .wait_outcome(ticket, timeout)
            .map_err(crate::device::wait_err)?;
        if !s.is_carried_out() {
            return Err(CliError::new(exit::REFUSED, format!("scale refused: {s}")));
        }
    }
    c.follow_trajectory(&t).map_err(|e| match e {
        TrajectorySendError::Invalid(e) => usage(e),
        TrajectorySendError::Send(e) => crate::device::command_err(e),
    })
}

/// After `--wait`'s sentence: each joint's final error.
pub fn print_errors(d: &Done) -> Result<(), CliError> {
    for (j, e) in d.errors().iter().enumerate() {
        if !e.is_nan() {
            outln!("  joint {j}: final error {e:+.4}")?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_hand_written_file_is_read_and_a_bad_one_named_by_its_line() {
        let t =
            parse("# a square wave\nt,j0,j2,v0,v2\n0.5, 0.1, 0.2, 0.2, 0.4\n\n1.0,0.2,0.4,0,0\n")
                .unwrap();
        assert_eq!(t.joints(), &[0, 2]);
        assert_eq!(t.len(), 2);
        assert_eq!(t.velocities(0), &[0.2, 0.4]);
        for (text, want) in [
            ("", "no header"),
            ("t,j0\n1.0,x\n", "line 2: \"x\" is not a number"),
            ("t,j0,v1\n", "for every joint"),
            (
                "t,j0\n1.0,0.1\n0.5,0.2\n",
                "line 3: point 1: time 0.5 s is not after",
            ),
            ("j0\n", "one column t"),
            ("t,k0\n", "not t, jN"),
            ("t,j0\n1,2,3\n", "3 values"),
        ] {
            let e = parse(text).unwrap_err().to_string();
            assert!(e.contains(want), "{text:?}: {e}");
        }
    }
}
