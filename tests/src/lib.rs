//! Shared helpers for hemi's integration tests.
