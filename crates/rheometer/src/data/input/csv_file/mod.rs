//! The measurement files (CSV): the rows they may still hold (`row_budget`) and reading them
//! (`measurements`).

pub(super) mod measurements;
pub(super) mod row_budget;
