//! SVG figures of the reports (plotters): simulation plots and work–precision charts.

pub mod accuracy;
pub mod simulate;
