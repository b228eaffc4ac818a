//! docs/reference/echo-json.md shows one object per interface: each has exactly the keys that
//! `Describe::json` prints (and `device`, which `limber echo` adds), nested objects and the
//! objects of arrays included. A field renamed in the code and not in the docs fails here.

use std::collections::BTreeSet;

use limber_interfaces::prelude::*;
use serde_json::Value;

fn key_set(v: &Value) -> BTreeSet<String> {
    limber_interfaces::reference::key_paths_of(v)
        .into_iter()
        .collect()
}

/// The JSON blocks of the page, in order.
fn documented() -> Vec<Value> {
    let page = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/reference/echo-json.md"),
    )
    .expect("docs/reference/echo-json.md");
    page.split("```json\n")
        .skip(1)
        .map(|b| serde_json::from_str(b.split("```").next().unwrap()).expect("a JSON block"))
        .collect()
}

#[test]
fn the_documented_schema_is_what_echo_prints() {
    let mut arm = ActArrayData {
        actuators_count: 1,
        ..ActArrayData::default()
    };
    arm.actuators[0].position = 0.5;
    let printed = [
        arm.json(),
        LimbData::default().json(),
        GripperData::default().json(),
        RangerData::default().json(),
    ];
    let docs = documented();
    assert_eq!(docs.len(), printed.len(), "one block per interface");
    for (doc, mut p) in docs.iter().zip(printed) {
        p["device"] = Value::from("x");
        assert_eq!(
            key_set(doc),
            key_set(&p),
            "documented:\n{doc:#}\nprinted:\n{p:#}"
        );
    }
}
