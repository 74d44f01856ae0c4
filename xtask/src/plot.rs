//! The plotting helpers of the page generators (`xtask/src/bin/{detection,estimation,
//! observer}_building.rs`, each including this file by `#[path]`): the charts' common frame,
//! a labelled line, the legend box. One copy, so the pages' SVGs keep one look.
#![allow(dead_code)] // each includer uses a different subset

use plotters::coord::Shift;
use plotters::coord::ranged1d::{AsRangedCoord, Ranged};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

/// A chart of the pages: SVG, `f64` time axis, `Y` the value axis.
pub type Chart<'a, 'b, Y> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, Y>>;
/// What the helpers return: plotters' errors, boxed.
pub type Res<T> = Result<T, Box<dyn std::error::Error>>;

/// A chart on `area` with the pages' frame: `caption` in 18 pt sans-serif, margin 15,
/// label areas 40 (x) and 60 (y) px, coordinates `x` by `y`.
pub fn chart<'a, 'b, Y: AsRangedCoord>(
    area: &'a DrawingArea<SVGBackend<'b>, Shift>,
    caption: &str,
    x: std::ops::Range<f64>,
    y: Y,
) -> Res<Chart<'a, 'b, Y::CoordDescType>> {
    Ok(ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 18))
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(x, y)?)
}

/// Draws the curve `pts` in `style`, named `name` in the legend (a 20 px stroke).
pub fn line<'a, 'b: 'a, Y: Ranged<ValueType = f64>>(
    chart: &mut Chart<'a, 'b, Y>,
    name: impl Into<String>,
    pts: Vec<(f64, f64)>,
    style: ShapeStyle,
) -> Res<()> {
    chart
        .draw_series(LineSeries::new(pts, style))?
        .label(name)
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
    Ok(())
}

/// The legend box at `position`: white, 85 % opaque, black border, 13 pt labels.
pub fn legend<'a, 'b: 'a, Y: Ranged<ValueType = f64>>(
    chart: &mut Chart<'a, 'b, Y>,
    position: SeriesLabelPosition,
) -> Res<()> {
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 13))
        .draw()?;
    Ok(())
}
