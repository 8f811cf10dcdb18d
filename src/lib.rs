//! nudge: interactive manipulation of rigid-body simulations in the terminal
//! (Popović, Seitz, Erdmann, Popović, Witkin, SIGGRAPH 2000).
//!
//! Data flows one way (DESIGN §9):
//! scene file → [`scene`] → [`sim`] (trajectory and tangents) → [`solve`]
//! (constraints, least-norm update) ← [`edit`] ← keys; rendering ([`view`],
//! `tui`) reads snapshots and never runs the simulator.

pub mod geometry;
pub mod math;
pub mod report;
pub mod scene;
pub mod sim;
pub mod bench;
pub mod controls;
pub mod edit;
pub mod solve;
pub mod svg;
pub mod tangent;
pub mod testkit;
pub mod view;
pub mod tui;
pub mod script;
