//! The cli tests in one binary (one link instead of 5): each file is a module
//! named after its former test binary; run one with `cargo test --release --test cli NAME::`.

#[path = "../probe/mod.rs"]
mod probe;

mod bad_input_t4;
mod cli_argument_probes;
mod cli_output_layer;
mod cli_output_safety;
mod design_cli;
mod diameter_level;
mod fit_from;
mod fit_html;
mod fit_report_findings;
mod flags_t4;
mod input_bounds;
mod input_loading;
mod input_messages;
mod input_plausibility;
mod input_units;
mod law_not_a_result;
mod reader_fuzz;
