//! The experiments file (TOML): messages for duplicate keys and for files that are not
//! experiments files (`syntax`), the keys of each table and the rules their values obey
//! (`schema`), the document read with spans (`spanned`), the `[uncertainty]` tables
//! (`uncertainty`) and one `[[experiment]]` table (`experiment`).

pub(super) mod experiment;
pub(super) mod schema;
pub(super) mod spanned;
pub(super) mod syntax;
pub(super) mod uncertainty;
