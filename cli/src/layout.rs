//! `limber layout`: the wire contract, for people and for generators.

use std::io::Write;

use clap::Args;
use limber_interfaces::{codegen, manifest};

use crate::CliError;

/// Arguments of `limber layout`.
#[derive(Debug, Args)]
#[group(multiple = false)]
pub struct LayoutArgs {
    /// Print the layout manifest as JSON (type name, size, alignment, every field's name,
    /// offset, size, type and array length; every constant).
    #[arg(long)]
    json: bool,
    /// Print the generated C header (what interfaces/include/limber.h holds).
    #[arg(long = "c-header")]
    c_header: bool,
    /// Print the generated Python ctypes module (what python/limber/_layout.py holds).
    #[arg(long)]
    python: bool,
    /// Print the reference page of the contract in Markdown (what docs/reference/wire.md
    /// holds): every struct with its fields' meanings, every code, the status sentences,
    /// and how `limber echo --json`'s keys map onto the C structs.
    #[arg(long)]
    markdown: bool,
    /// Print the URDF limber uses for an arm (e.g. pioneer/actarray/0; the one `limber
    /// view` serves): its driver's chain, or by the robot name (pioneer, simarm) when no
    /// driver runs.
    #[arg(long, value_name = "DEVICE")]
    urdf: Option<String>,
}

/// Runs `limber layout`.
pub fn run(args: LayoutArgs) -> Result<(), CliError> {
    let m = manifest();
    let text = if let Some(device) = &args.urdf {
        let name = device.parse().map_err(|e: limber_services::NameError| {
            CliError::new(crate::exit::USAGE, e.to_string())
        })?;
        let domain = crate::domain()?;
        limber_record::view::urdf_of_device(&domain, &name)
            .map_err(|e| CliError::new(crate::exit::USAGE, e.to_string()))?
    } else if args.json {
        m.to_json() + "\n"
    } else if args.c_header {
        codegen::c_header(&m)
    } else if args.python {
        codegen::python_module(&m)
    } else if args.markdown {
        limber_interfaces::reference::markdown(&m)
    } else {
        catalogue(&m)
    };
    std::io::stdout()
        .write_all(text.as_bytes())
        .map_err(crate::out::stdout_error)
}

fn catalogue(m: &limber_interfaces::Manifest) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "limber wire contract, layout version {} ({} structs)\n",
        m.layout_version,
        m.structs.len()
    );
    let _ = writeln!(
        s,
        "{:<28} {:<36} {:>6} {:>5}",
        "struct", "type name", "size", "align"
    );
    for st in &m.structs {
        let _ = writeln!(
            s,
            "{:<28} {:<36} {:>6} {:>5}",
            st.name, st.type_name, st.size, st.align
        );
    }
    let _ = writeln!(s, "\nconstants:");
    for g in &m.constants {
        let list: Vec<String> = g
            .constants
            .iter()
            .map(|c| format!("{}={}", c.name, c.value))
            .collect();
        let _ = writeln!(s, "  {:<16} {}", g.name, list.join(" "));
    }
    s
}
