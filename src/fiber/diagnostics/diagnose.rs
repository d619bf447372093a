//! Diagnosis (in progress).
