//! Scenes as data (the `mpm-scene` crate, run by `mpm-dispatch`, written
//! by this crate's program): a whole problem — mesh, materials, bodies, node sets,
//! boundary conditions, loads with load curves, solver and outputs — in
//! one TOML file, run without writing Rust.
//!
//! [`format`] is what the file deserialises into (unknown keys refused);
//! [`build`] checks it across sections and builds the grid, points,
//! conditions and loads, every error naming its place in the file or the
//! `--set` override it comes from; [`run`] runs the result with the
//! variant and materials it names. The key-by-key reference is the guide
//! page `docs/src/guide/scenes.md`.
//!
//! ```
//! use mpm_cases::scene::{self, Problem};
//! use mpm_cases::run::RunControl;
//!
//! let text = r#"
//! [mesh]
//! origin = [0.0, 0.0]
//! size = [1.0, 10.0]
//! cells = [1, 4]
//!
//! [[material]]
//! name = "soil"
//! model = "hencky"
//! youngs_modulus = 1e6
//! poisson_ratio = 0.0
//! density = 80.0
//!
//! [[body]]
//! name = "column"
//! material = "soil"
//! region = { box = { lower = [0.0, 0.0], upper = [1.0, 10.0] } }
//!
//! [[boundary]]
//! set = "y_min"
//! kind = "fixed"
//!
//! [[boundary]]
//! set = "x_min"
//! kind = "roller"
//!
//! [[boundary]]
//! set = "x_max"
//! kind = "roller"
//!
//! [[load]]
//! kind = "gravity"
//! acceleration = [0.0, -10.0]
//! "#;
//! let (scene, source) = scene::parse(text, "column.toml", &[])?;
//! let problem = Problem::<2>::build(&scene, &source, scene.solver.padding())?;
//! let out = scene::run(&problem, &RunControl::default(), |_, _, _| Ok(()))?;
//! // The base carries the weight: 80 kg/m³ × 10 m/s² × 10 m².
//! let reaction = out.reports.last().unwrap().reaction;
//! assert!((reaction[1] - 8000.0).abs() < 1e-6 * 8000.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub use mpm_dispatch::{explicit, explicit_law};
pub use mpm_output::png;
pub use mpm_scene::{SceneError, build, format, region};
mod program;
pub mod ranks;
pub mod strength_reduction;

pub use mpm_dispatch::{
    ExplicitEvent, ExplicitFrame, ExplicitObserver, ExplicitOutput, RunExplicit, RunScene, run,
    run_explicit,
};
pub use mpm_scene::{
    ExplicitSetup, Problem, ReactionOutput, Scene, SceneConstraints, SceneMotion, TimedForces,
    dimension, parse,
};
pub use program::run_file;
