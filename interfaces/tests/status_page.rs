//! docs/reference/status-codes.md explains every status code in words; its table has
//! exactly the codes and names of the contract's `STATUS` group (a code added or renamed in
//! the code and not on the page fails here). The generated docs/reference/wire.md lists
//! them too, from the same group.

use std::collections::BTreeSet;

#[test]
fn the_status_page_names_every_code_of_the_contract() {
    let page = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/reference/status-codes.md"),
    )
    .expect("docs/reference/status-codes.md");
    // Rows "| 13 | `CLAMPED` | meaning |".
    let documented: BTreeSet<(i64, String)> = page
        .lines()
        .filter_map(|l| {
            let cells: Vec<&str> = l.split('|').map(str::trim).collect();
            let code = cells.get(1)?.parse().ok()?;
            let name = cells.get(2)?.trim_matches('`').to_string();
            Some((code, name))
        })
        .collect();
    let m = limber_interfaces::manifest();
    let group = m
        .constants
        .iter()
        .find(|g| g.name == "STATUS")
        .expect("the STATUS group");
    let contract: BTreeSet<(i64, String)> = group
        .constants
        .iter()
        .map(|c| (c.value, c.name.to_string()))
        .collect();
    assert_eq!(documented, contract);
}
