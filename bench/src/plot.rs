//! The SVG plot: the latency percentile curve of every measurement. x: percentile on a
//! "nines" scale (0 = p0, 1 = p90, 2 = p99, 3 = p99.9, ...), y: latency, log scale.

use std::path::Path;

use plotters::prelude::*;

use crate::BenchError;
use crate::report::Report;
use crate::stats::fmt_ns;

fn nines(percentile: f64) -> f64 {
    let rest = (1.0 - percentile / 100.0).max(1e-6);
    -rest.log10()
}

/// Draws every measurement's curve of `report` into the SVG file `path`.
pub fn draw(path: &Path, report: &Report) -> Result<(), BenchError> {
    let err = |e: String| BenchError::Plot {
        path: path.to_path_buf(),
        reason: e,
    };
    // The last point of every curve is the max: draw it at the nines of 1/count.
    let series: Vec<(String, Vec<(f64, f64)>)> = report
        .measurements
        .iter()
        .filter(|r| r.summary.count > 0)
        .map(|r| {
            let n = r.summary.count as f64;
            let pts = r
                .curve
                .iter()
                .map(|p| {
                    let x = if p.percentile >= 100.0 {
                        n.log10()
                    } else {
                        nines(p.percentile)
                    };
                    (x, (p.ns.max(1)) as f64)
                })
                .collect();
            (format!("{} [{}]", r.label, r.strategy.name()), pts)
        })
        .collect();
    if series.is_empty() {
        return Err(err("no measurements to plot".into()));
    }
    let xmax = series
        .iter()
        .flat_map(|(_, p)| p.iter().map(|q| q.0))
        .fold(1.0f64, f64::max)
        .ceil();
    let ymin = series
        .iter()
        .flat_map(|(_, p)| p.iter().map(|q| q.1))
        .fold(f64::MAX, f64::min)
        * 0.8;
    let ymax = series
        .iter()
        .flat_map(|(_, p)| p.iter().map(|q| q.1))
        .fold(1.0f64, f64::max)
        * 1.25;
    let height = 700 + 18 * series.len() as u32;
    let root = SVGBackend::new(path, (1400, height)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(e.to_string()))?;
    let title = format!(
        "limber latency percentiles — {} ({} cores, {})",
        report.machine.cpu, report.machine.cores, report.machine.kernel
    );
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 18))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(80)
        .build_cartesian_2d(0f64..xmax, (ymin.max(1.0)..ymax).log_scale())
        .map_err(|e| err(e.to_string()))?;
    chart
        .configure_mesh()
        .x_desc("percentile")
        .y_desc("latency")
        .x_labels(xmax as usize + 1)
        .x_label_formatter(&|x| {
            let p = 100.0 * (1.0 - 10f64.powf(-x));
            if *x < 0.5 {
                "p0".to_string()
            } else {
                format!("p{}", trim(p))
            }
        })
        .y_label_formatter(&|y| fmt_ns(*y as u64))
        .draw()
        .map_err(|e| err(e.to_string()))?;
    for (i, (label, pts)) in series.into_iter().enumerate() {
        let color = Palette99::pick(i).to_rgba();
        chart
            .draw_series(LineSeries::new(pts, color.stroke_width(2)))
            .map_err(|e| err(e.to_string()))?
            .label(label)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
            });
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 12))
        .draw()
        .map_err(|e| err(e.to_string()))?;
    root.present().map_err(|e| err(e.to_string()))?;
    Ok(())
}

fn trim(p: f64) -> String {
    let s = format!("{p:.4}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}
