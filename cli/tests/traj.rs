//! `limber actarray DEV traj FILE` and `scale F` (issue 28) against `limber simarm`: a
//! hand-written CSV trajectory followed to the end with `--wait` (the result and each
//! joint's final error), a bad file refused naming its line, an unknown joint refused by
//! the driver with the cause, the scaling said (and clamped above 1).

use limber_services::Domain;

mod common;
use common::{Bg, limber, stderr, stdout};

/// A file of this test's own (removed when dropped).
struct TempFile(std::path::PathBuf);

impl TempFile {
    fn new(name: &str, text: &str) -> TempFile {
        let p = std::env::temp_dir().join(format!("limber-traj-{}-{name}", std::process::id()));
        std::fs::write(&p, text).expect("write the trajectory file");
        TempFile(p)
    }
    fn path(&self) -> &str {
        self.0.to_str().expect("utf-8 path")
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

#[test]
fn a_csv_trajectory_is_followed_and_its_result_said() {
    let d = Domain::unique_for_test();
    let dom = d.name();
    let mut sim = Bg::spawn(dom, &["simarm"]);
    sim.line(|l| l.ends_with("ready"));
    // Joints 0 (the base, about the vertical) and 5 (the wrist): cubic, ending at rest.
    let file = TempFile::new(
        "ok.csv",
        "# pan and wrist\nt,j0,j5,v0,v5\n0.4,0.2,0.1,0.5,0.25\n0.8,0.4,0.2,0,0\n",
    );
    let o = limber(
        dom,
        &[
            "actarray",
            "simarm/actarray/0",
            "traj",
            file.path(),
            "--goal-tolerance",
            "0.001",
            "--path-tolerance",
            "0.05",
            "--wait",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    assert!(
        out.starts_with("ok\ndone: reached the goal within the tolerance"),
        "{out}"
    );
    assert!(out.contains("  joint 0: final error +0.0000"), "{out}");
    assert!(out.contains("  joint 5: final error"), "{out}");

    // A bad file: exit 2, the line named, nothing sent.
    let bad = TempFile::new("bad.csv", "t,j0\n0.5,0.1\n0.4,0.2\n");
    let o = limber(dom, &["actarray", "simarm/actarray/0", "traj", bad.path()]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("line 3: point 1: time 0.4 s is not after the previous point's 0.5 s"),
        "{}",
        stderr(&o)
    );

    // A joint the arm does not have: refused by the driver with the cause.
    let unknown = TempFile::new("unknown.csv", "t,j0,j12\n1.0,0.1,0.1\n");
    let o = limber(
        dom,
        &["actarray", "simarm/actarray/0", "traj", unknown.path()],
    );
    assert_eq!(o.status.code(), Some(5), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("refused: unknown joint"),
        "{}",
        stderr(&o)
    );

    // The scaling.
    let o = limber(dom, &["actarray", "simarm/actarray/0", "scale", "0.5"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(stdout(&o), "ok\n");
    let o = limber(dom, &["actarray", "simarm/actarray/0", "scale", "2"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(stdout(&o), "ok, clamped to the limit\n");
}
