//! Helpers shared by the benches: environment settings, medians, the output folder and the
//! plots' font and colors. Each bench uses part of them.
#![allow(dead_code)]

pub mod reference;
// The window room's generator (its sky and sun), shared with the tests.
#[path = "../../tests/common/obj_text.rs"]
pub mod obj_text;
#[path = "../../tests/common/window_room.rs"]
pub mod window_room;

use plotters::coord::CoordTranslate;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// The value of the environment variable `name`, or `default` when it is not set. Panics on
/// a value that does not parse: a typo should not silently run the default.
pub fn env_value<T: std::str::FromStr>(name: &str, default: T) -> T {
    match std::env::var(name) {
        Ok(text) => text
            .trim()
            .parse()
            .unwrap_or_else(|_| panic!("{name}={text:?} is not a valid number")),
        Err(_) => default,
    }
}

/// The comma-separated names in `name`, or `default` when it is not set.
pub fn env_names(name: &str, default: &[&str]) -> Vec<String> {
    match std::env::var(name) {
        Ok(text) => text
            .split(',')
            .map(str::trim)
            .filter(|s| !s.is_empty())
            .map(String::from)
            .collect(),
        Err(_) => default.iter().map(|s| s.to_string()).collect(),
    }
}

/// The median (the upper one of an even count); sorts `values`.
pub fn median(values: &mut [f64]) -> f64 {
    values.sort_by(|a, b| a.total_cmp(b));
    values[values.len() / 2]
}

/// `target/mlt-bench`, in the target directory cargo uses.
pub fn output_dir() -> PathBuf {
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("target"));
    target.join("mlt-bench")
}

/// The family the plots' text asks for; `register_plot_font` registers a font file under it.
pub const FONT_FAMILY: &str = "sans-serif";
const FONT_CANDIDATES: &[&str] = &[
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
    "/System/Library/Fonts/Supplemental/Arial.ttf",
    "C:\\Windows\\Fonts\\arial.ttf",
];

/// Registers the first readable font of `MLT_BENCH_FONT` or the usual system paths; returns
/// its path, or `None` when there is none and a plot must do without text.
pub fn register_plot_font() -> Option<PathBuf> {
    let candidates: Vec<PathBuf> = match std::env::var_os("MLT_BENCH_FONT") {
        Some(path) => vec![PathBuf::from(path)],
        None => FONT_CANDIDATES.iter().map(PathBuf::from).collect(),
    };
    candidates.into_iter().find(|path| {
        let Ok(bytes) = std::fs::read(path) else {
            return false;
        };
        // plotters keeps fonts for the life of the program and takes only 'static bytes.
        let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
        plotters::style::register_font(FONT_FAMILY, FontStyle::Normal, bytes).is_ok()
    })
}

/// Colors of a plot's series, by index (repeating past the end): distinct and dark enough
/// to read on white.
const SERIES_COLORS: &[RGBColor] = &[
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(0, 0, 0),
    RGBColor(255, 187, 120),
    RGBColor(174, 199, 232),
    RGBColor(152, 223, 138),
    RGBColor(255, 152, 150),
    RGBColor(197, 176, 213),
    RGBColor(196, 156, 148),
    RGBColor(219, 219, 141),
    RGBColor(158, 218, 229),
];

pub fn series_color(index: usize) -> RGBColor {
    SERIES_COLORS[index % SERIES_COLORS.len()]
}

/// Registers a font for a plot (see `register_plot_font`) and says whether there is one;
/// without one, prints which color stands for which of `series` (the plot has no legend).
pub fn plot_font_or_color_key<'a>(series: impl IntoIterator<Item = &'a str>) -> bool {
    if register_plot_font().is_some() {
        return true;
    }
    println!(
        "no font found (set MLT_BENCH_FONT to a .ttf file): the plot has no title, labels or legend"
    );
    for (index, name) in series.into_iter().enumerate() {
        let RGBColor(r, g, b) = series_color(index);
        println!("  {name}: color #{r:02x}{g:02x}{b:02x}");
    }
    false
}

/// The legend of a chart's labelled series, in its upper right corner.
pub fn draw_legend<'a, DB, CT>(
    chart: &mut ChartContext<'a, DB, CT>,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>>
where
    DB: DrawingBackend + 'a,
    CT: CoordTranslate,
{
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font((FONT_FAMILY, 14))
        .draw()
}
