//! BDPT's converged estimate of the door-ajar image (tests/common/door_ajar.rs), cached:
//! written by `MLT_REGENERATE_DOOR_AJAR_REFERENCE=1 cargo test --test brightness --
//! the_cached_reference`, which renders `SEEDS.len()` BDPT images of `SIZE`² pixels at
//! `SPP` samples (max depth 5). Everything below `source` is generated.
// Each test file and bench uses a part of these helpers.
#![allow(dead_code)]

use super::stats::CachedEstimate;

pub const SIZE: u32 = 128;
pub const SPP: u32 = 128;
pub const SEEDS: std::ops::Range<u64> = 5000..5032;

/// This file's text for `reference`, whose image luminance has standard error
/// `luminance_relative_error` (relative).
pub fn source(reference: &CachedEstimate<4>, luminance_relative_error: f64) -> String {
    let text = include_str!("door_ajar_reference.rs");
    let marker = "\n// Generated: do not edit.\n";
    let head = &text[..text.find(marker).expect("the generated part's marker") + 1];
    format!(
        "{head}// Generated: do not edit.\n\
         /// The standard error of the image's luminance over the luminance (from the spread of the renders').\n\
         pub const LUMINANCE_RELATIVE_ERROR: f64 = {luminance_relative_error:e};\n\
         #[rustfmt::skip]\n\
         pub const BDPT: CachedEstimate<4> = CachedEstimate {{\n    \
         mean: {:?},\n    mean_variance: {:?},\n    cells: {:?},\n    cell_variances: {:?},\n}};\n",
        reference.mean, reference.mean_variance, reference.cells, reference.cell_variances
    )
}

// Generated: do not edit.
/// The standard error of the image's luminance over the luminance (from the spread of the renders').
pub const LUMINANCE_RELATIVE_ERROR: f64 = 3.914267718784176e-4;
#[rustfmt::skip]
pub const BDPT: CachedEstimate<4> = CachedEstimate {
    mean: [0.1777787622511796, 0.13146743352967555, 0.08849562473131073],
    mean_variance: [4.4476885344317035e-9, 2.7310206716890195e-9, 1.4775745551332561e-9],
    cells: [[[0.07898640818176439, 0.05836125470335762, 0.038760492358407284], [0.11396539349640022, 0.08503432582956805, 0.0571370071870021], [0.11503118567705428, 0.08837848839773699, 0.061074734014120224], [0.0828946793504457, 0.0646271025002676, 0.04516264187858354]], [[0.07508503571337144, 0.05680830478748078, 0.03854055669294354], [0.7100519275244395, 0.5048329301384982, 0.3254890294299173], [0.1252820353346351, 0.08403648908569039, 0.05027028887080576], [0.06718767808270343, 0.052221375615701504, 0.036266123570840136]], [[0.05491446024430502, 0.039002493261556026, 0.024833094354800522], [0.6605721902529993, 0.4938678317452876, 0.33915418199631375], [0.2770619736057256, 0.20851736816156574, 0.14396656269325092], [0.06595500703093649, 0.05097767563399813, 0.03535246458384478]], [[0.056902553257373256, 0.04000222342915549, 0.025496441931263547], [0.10553016268406168, 0.07964054008047583, 0.05511014886856458], [0.14298614792386388, 0.11090184895908806, 0.07881337342820416], [0.11205335765879454, 0.0862686841453808, 0.060502853842109516]]],
    cell_variances: [[[2.1259876301475378e-8, 1.2733645086247516e-8, 6.441258010475173e-9], [3.181977724791452e-8, 1.9416476419724326e-8, 9.650705698687046e-9], [3.539331588008742e-8, 2.0220562944177428e-8, 9.519803143601097e-9], [1.987474676448558e-8, 1.2463248436864029e-8, 6.305061054582584e-9]], [[3.363645351721183e-8, 2.0418733752527208e-8, 1.010908682762613e-8], [1.4745893038570173e-7, 6.69662219212832e-8, 2.9936704887567686e-8], [3.1167890002599236e-8, 1.5307293460523386e-8, 6.398177398830341e-9], [2.502499619247163e-8, 1.5186794228146504e-8, 7.380260984876566e-9]], [[1.3197252909228568e-8, 7.311282859810195e-9, 3.3905713898770247e-9], [1.8163785705059408e-7, 9.722598599666236e-8, 4.712071629653594e-8], [6.277711962340044e-8, 3.9747983616333456e-8, 2.214510845251885e-8], [7.67682193391473e-9, 4.57372419092154e-9, 2.2306970334105442e-9]], [[1.1258910831065535e-8, 5.324417584679702e-9, 2.1418329314834734e-9], [1.9027974787042016e-8, 1.1316155868819518e-8, 6.031282738448133e-9], [1.7923395644825978e-8, 1.0993354524801027e-8, 5.852685244738533e-9], [1.467648310070522e-8, 8.44412162225127e-9, 4.1808123172828115e-9]]],
};
