//! URDF in: the serial chain of a URDF file as limber-kinematics' [`Chain`] (what
//! `limber simarm --urdf FILE` simulates).
//!
//! The chain runs from the root link (the one no joint has as its child) down while each
//! link has exactly one child joint; the link where the tree branches (a hand with two
//! fingers) or ends is the tool. Revolute, continuous (limits ±2π) and prismatic joints are
//! the chain's joints, with their origin, axis, limits and velocity; fixed joints are folded
//! into the next joint's origin (or into the tool frame after the last one). A floating or
//! planar joint, a joint without its limits, a missing link and malformed XML or numbers are
//! refused, naming what is wrong.

use std::collections::HashMap;
use std::path::Path;

use limber_kinematics::chain::{Chain, ChainLoadError};
use nalgebra::{Rotation3, Vector3};
use thiserror::Error;

/// A URDF that limber cannot simulate.
#[derive(Debug, Error)]
pub enum UrdfError {
    /// The file could not be read.
    #[error("cannot read {path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// It is not well-formed XML.
    #[error("not well-formed XML: {0}")]
    Xml(#[from] roxmltree::Error),
    /// Its root element is not `<robot>`.
    #[error("the root element is <{0}>, not <robot>")]
    NotRobot(String),
    /// An element lacks something it needs, or has a value that is not one.
    #[error("joint {joint:?}: {what}")]
    Joint {
        /// The joint.
        joint: String,
        /// What is wrong.
        what: String,
    },
    /// No chain: no root link, several, or no movable joint on the way.
    #[error("no serial chain: {0}")]
    Chain(String),
    /// The chain is not one limber accepts (limits, speeds, too many joints).
    #[error("the chain is not valid: {0}")]
    Invalid(#[from] ChainLoadError),
}

struct Joint<'a> {
    name: &'a str,
    kind: &'a str,
    parent: &'a str,
    child: &'a str,
    xyz: Vector3<f64>,
    rot: Rotation3<f64>,
    axis: Vector3<f64>,
    limits: Option<(f64, f64, f64)>,
}

fn numbers(joint: &str, what: &str, text: &str, n: usize) -> Result<Vec<f64>, UrdfError> {
    let v: Result<Vec<f64>, _> = text.split_whitespace().map(str::parse::<f64>).collect();
    match v {
        Ok(v) if v.len() == n && v.iter().all(|x| x.is_finite()) => Ok(v),
        _ => Err(UrdfError::Joint {
            joint: joint.into(),
            what: format!("{what} {text:?} is not {n} finite numbers"),
        }),
    }
}

fn parse_joint<'a>(j: roxmltree::Node<'a, 'a>) -> Result<Joint<'a>, UrdfError> {
    let name = j.attribute("name").unwrap_or("");
    let bad = |what: String| UrdfError::Joint {
        joint: name.into(),
        what,
    };
    let kind = j.attribute("type").ok_or_else(|| bad("no type".into()))?;
    let child_el = |tag: &str| j.children().find(|c| c.has_tag_name(tag));
    let link_of = |tag: &str| {
        child_el(tag)
            .and_then(|e| e.attribute("link"))
            .ok_or_else(|| bad(format!("no <{tag} link=...>")))
    };
    let (parent, child) = (link_of("parent")?, link_of("child")?);
    let (mut xyz, mut rot) = (Vector3::zeros(), Rotation3::identity());
    if let Some(o) = child_el("origin") {
        if let Some(t) = o.attribute("xyz") {
            let v = numbers(name, "origin xyz", t, 3)?;
            xyz = Vector3::new(v[0], v[1], v[2]);
        }
        if let Some(t) = o.attribute("rpy") {
            let v = numbers(name, "origin rpy", t, 3)?;
            rot = Rotation3::from_euler_angles(v[0], v[1], v[2]);
        }
    }
    let axis = match child_el("axis").and_then(|a| a.attribute("xyz")) {
        Some(t) => {
            let v = numbers(name, "axis", t, 3)?;
            Vector3::new(v[0], v[1], v[2])
        }
        None => Vector3::x(),
    };
    let limit = child_el("limit");
    let attr = |a: &str| -> Result<Option<f64>, UrdfError> {
        match limit.and_then(|l| l.attribute(a)) {
            Some(t) => Ok(Some(numbers(name, &format!("limit {a}"), t, 1)?[0])),
            None => Ok(None),
        }
    };
    let limits = match kind {
        "revolute" | "prismatic" => {
            let (Some(lo), Some(hi)) = (attr("lower")?, attr("upper")?) else {
                return Err(bad(format!("a {kind} joint needs <limit lower upper>")));
            };
            Some((lo, hi, attr("velocity")?.unwrap_or(1.0)))
        }
        "continuous" => Some((
            -core::f64::consts::TAU,
            core::f64::consts::TAU,
            attr("velocity")?.unwrap_or(1.0),
        )),
        "fixed" => None,
        other => {
            return Err(bad(format!(
                "type {other:?} is not supported (revolute, continuous, prismatic, fixed)"
            )));
        }
    };
    Ok(Joint {
        name,
        kind,
        parent,
        child,
        xyz,
        rot,
        axis,
        limits,
    })
}

/// The chain of a URDF text, as the TOML of a chain file (`drivers/kinematics/chains/`).
pub fn chain_toml_from_urdf(text: &str) -> Result<String, UrdfError> {
    let doc = roxmltree::Document::parse(text)?;
    let robot = doc.root_element();
    if !robot.has_tag_name("robot") {
        return Err(UrdfError::NotRobot(robot.tag_name().name().to_string()));
    }
    let name = robot.attribute("name").unwrap_or("urdf");
    let joints: Vec<Joint> = robot
        .children()
        .filter(|c| c.has_tag_name("joint"))
        .map(parse_joint)
        .collect::<Result<_, _>>()?;
    let links: Vec<&str> = robot
        .children()
        .filter(|c| c.has_tag_name("link"))
        .filter_map(|l| l.attribute("name"))
        .collect();
    let mut by_parent: HashMap<&str, Vec<&Joint>> = HashMap::new();
    for j in &joints {
        for l in [j.parent, j.child] {
            if !links.contains(&l) {
                return Err(UrdfError::Joint {
                    joint: j.name.into(),
                    what: format!("link {l:?} is not defined"),
                });
            }
        }
        by_parent.entry(j.parent).or_default().push(j);
    }
    let roots: Vec<&str> = links
        .iter()
        .copied()
        .filter(|l| !joints.iter().any(|j| j.child == *l))
        .collect();
    let [root] = roots.as_slice() else {
        return Err(UrdfError::Chain(format!(
            "{} root links ({roots:?}); one is needed",
            roots.len()
        )));
    };
    // Down from the root while the way is single; fixed joints fold into the next one.
    let mut toml = String::new();
    toml.push_str(&format!(
        "name = {:?}\ndescription = \"from URDF robot {name}\"",
        name
    ));
    toml.push('\n');
    let (mut pending_p, mut pending_r) = (Vector3::zeros(), Rotation3::identity());
    let (mut link, mut movable) = (*root, 0usize);
    let mut seen = vec![link];
    while let Some([j]) = by_parent.get(link).map(Vec::as_slice) {
        // A joint's frame after the fixed joints before it.
        let p = pending_p + pending_r * j.xyz;
        let r = pending_r * j.rot;
        link = j.child;
        if seen.contains(&link) {
            return Err(UrdfError::Chain(format!("link {link:?} is reached twice")));
        }
        seen.push(link);
        let Some((min, max, speed)) = j.limits else {
            (pending_p, pending_r) = (p, r);
            continue;
        };
        let (ro, pi, ya) = r.euler_angles();
        let kind = if j.kind == "prismatic" {
            "linear"
        } else {
            "rotary"
        };
        toml.push_str(&format!("\n[[joints]]\nname = {:?}\ntype = \"{kind}\"\nxyz = [{:?}, {:?}, {:?}]\nrpy = [{ro:?}, {pi:?}, {ya:?}]\naxis = [{:?}, {:?}, {:?}]\nmin = {min:?}\nmax = {max:?}\nmax_speed = {speed:?}",
            j.name, p.x, p.y, p.z, j.axis.x, j.axis.y, j.axis.z
        ));
        toml.push('\n');
        movable += 1;
        (pending_p, pending_r) = (Vector3::zeros(), Rotation3::identity());
    }
    if movable == 0 {
        return Err(UrdfError::Chain(format!(
            "no revolute, continuous or prismatic joint below link {root:?}"
        )));
    }
    let (ro, pi, ya) = pending_r.euler_angles();
    toml.push_str(&format!(
        "\n[tool]\nxyz = [{:?}, {:?}, {:?}]\nrpy = [{ro:?}, {pi:?}, {ya:?}]",
        pending_p.x, pending_p.y, pending_p.z
    ));
    toml.push('\n');
    Ok(toml)
}

/// The chain of URDF text.
pub fn chain_from_urdf(text: &str) -> Result<Chain, UrdfError> {
    Ok(Chain::from_toml_str(&chain_toml_from_urdf(text)?)?)
}

/// The chain of the URDF file `path`.
pub fn chain_from_urdf_file(path: &Path) -> Result<Chain, UrdfError> {
    let text = std::fs::read_to_string(path).map_err(|source| UrdfError::Io {
        path: path.display().to_string(),
        source,
    })?;
    chain_from_urdf(&text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limbers_own_urdf_reads_back_as_the_same_chain() {
        for chain in [
            Chain::default_6dof(),
            Chain::default_7dof(),
            Chain::pioneer5(),
        ] {
            let urdf = crate::urdf::urdf_of_chain(&chain, "arm");
            let back = chain_from_urdf(&urdf).unwrap();
            assert_eq!(back.dof(), chain.dof());
            // The same forward kinematics at the home pose and at another one.
            let home = chain.home();
            let q: Vec<f64> = home.as_slice().iter().map(|v| v + 0.1).collect();
            for q in [home.as_slice().to_vec(), q] {
                let (a, b) = (chain.fk(&q).unwrap(), back.fk(&q).unwrap());
                assert!(a.position_error(&b) < 1e-9, "{}", chain.name());
                assert!(a.orientation_error(&b) < 1e-9, "{}", chain.name());
            }
        }
    }

    #[test]
    fn malformed_urdfs_are_refused_naming_what_is_wrong() {
        let cases = [
            ("<robot", "not well-formed XML"),
            ("<model/>", "not <robot>"),
            ("<robot name='r'><link name='a'/></robot>", "no revolute"),
            (
                "<robot name='r'><link name='a'/><link name='b'/><joint name='j' type='revolute'><parent link='a'/><child link='b'/></joint></robot>",
                "needs <limit lower upper>",
            ),
            (
                "<robot name='r'><link name='a'/><link name='b'/><joint name='j' type='floating'><parent link='a'/><child link='b'/></joint></robot>",
                "\"floating\" is not supported",
            ),
            (
                "<robot name='r'><link name='a'/><joint name='j' type='fixed'><parent link='a'/><child link='c'/></joint></robot>",
                "link \"c\" is not defined",
            ),
            (
                "<robot name='r'><link name='a'/><link name='b'/><joint name='j' type='revolute'><parent link='a'/><child link='b'/><origin xyz='1 nan 0'/><limit lower='-1' upper='1'/></joint></robot>",
                "not 3 finite numbers",
            ),
            (
                "<robot name='r'><link name='a'/><link name='b'/><joint name='j' type='revolute'><parent link='a'/><child link='b'/><limit lower='1' upper='-1'/></joint></robot>",
                "not valid",
            ),
        ];
        for (text, says) in cases {
            let e = chain_from_urdf(text).unwrap_err().to_string();
            assert!(e.contains(says), "{text}: {e}");
        }
    }
}
