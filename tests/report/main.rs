//! The report layer shared by the rheometer: figures (plot) and the HTML page.

mod html_page;
mod plot;
