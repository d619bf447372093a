//! The report: what the program writes for people and for the next step — figures, the HTML
//! report page, numbers for people, JSON reports, and the output layer every file goes through.
//!
//! * [`output_files`]: checks of every output before the work, temporary-then-rename writing
//!   of regular files, special files written in place;
//! * [`output`]: the rheometer's use of it (never overwriting an input);
//! * [`plot`]: the figure library (panels, axes, legends, heatmaps; PNG/SVG);
//! * [`html_page`]: the printable, self-contained HTML page;
//! * [`format`](mod@format): numbers for people;
//! * [`report_json`]: the stamp of every JSON report (schema version, kind, program);
//! * `serde_nan`: non-finite numbers in JSON;
//! * [`figures`]: profile, fit and landscape figures (PNG/SVG);
//! * [`flow_curve_figure`]: the flow curve `η_E(ε̇)` with its bands (PNG/SVG);
//! * [`fit_html`]: the HTML report of a fit (self-contained page, from the fit's values).

pub mod figures;
pub mod fit_html;
pub mod flow_curve_figure;
pub mod format;
pub mod html_page;
pub mod output;
pub mod output_files;
pub mod plot;
pub mod report_json;
pub(crate) mod serde_nan;
