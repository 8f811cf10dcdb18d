//! nudge: interactive manipulation of rigid-body simulations in the terminal
//! (Popović, Seitz, Erdmann, Popović, Witkin, SIGGRAPH 2000).
//!
//! Data flows one way (docs/design.md):
//! scene file → [`scene`] → [`sim`] (trajectory and tangents) → [`solve`]
//! (constraints, least-norm update) ← [`edit`] ← keys; rendering ([`view`],
//! `tui`) reads snapshots and never runs the simulator.

pub mod bench;
pub mod check;
pub mod controls;
pub mod edit;
pub mod estimate;
pub mod explore;
pub mod export;
pub mod files;
pub mod geometry;
pub mod math;
pub mod profile;
pub mod report;
pub mod scene;
pub mod script;
pub mod sim;
pub mod solve;
pub mod svg;
pub mod tangent;
pub mod testkit;
pub mod tui;
pub mod view;
