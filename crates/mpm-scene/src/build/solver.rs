//! The `[solver]` keys of the variant (basis, formulation, locking,
//! domain update) and of the implicit solver: load stepping and Newton
//! controls, each value checked at its key.

use mpm_solver::{LoadStepping, NewtonOptions};

use super::{Check, PetscRequest};
use crate::SceneError;
use crate::format::{LinearKind, SolverSpec};
use crate::source::SceneSource;
use crate::variant::Variant;
use toml::Spanned;

/// The variant `s` names; its basis and domain rule must fit whatever the
/// mesh (the rest of the table needs the mesh and is checked with it).
///
/// # Errors
/// [`SceneError::Scene`] at `domain_update`.
pub(super) fn variant(s: &SolverSpec, src: &SceneSource) -> Result<Variant, SceneError> {
    let variant = Variant {
        basis: s.basis(),
        formulation: *s.formulation.get_ref(),
        locking: *s.locking.get_ref(),
        domain_update: *s.domain_update.get_ref(),
        gimp_volume: *s.gimp_volume.get_ref(),
    };
    if let Some(message) =
        crate::rules::domain_update_fits_basis(&variant, crate::rules::Context::ImplicitGrid)
    {
        return Err(src.at(&s.domain_update, message));
    }
    Ok(variant)
}

/// The load stepping and Newton options of `s`; `grid`: the scene's mesh
/// is a regular grid (the ghost penalty acts on its cells' faces).
///
/// # Errors
/// [`SceneError::Scene`] at the key whose value is out of range or does
/// not apply.
pub(super) fn newton_and_stepping(
    s: &SolverSpec,
    src: &SceneSource,
    grid: bool,
) -> Result<(LoadStepping, NewtonOptions), SceneError> {
    let check = Check { src };
    let steps = check.at_least(&s.steps, 1, "solver `steps`")?;
    let initial = 1.0 / steps as f64;
    let max = match &s.max_increment {
        Some(v) => check.positive(v, "solver `max_increment`")?,
        None => initial,
    };
    let min = match &s.min_increment {
        Some(v) => check.positive(v, "solver `min_increment`")?,
        None => initial / 1024.0,
    };
    if !(min <= initial && initial <= max && max <= 1.0) {
        let at = s.max_increment.as_ref().or(s.min_increment.as_ref());
        return Err(src.error(
            at.map(Spanned::span),
            &format!("load increments need min_increment ({min}) <= 1/steps ({initial}) <= max_increment ({max}) <= 1"),
        ));
    }
    if min < mpm_solver::MIN_LOAD_INCREMENT {
        let at = s
            .min_increment
            .as_ref()
            .map_or(s.steps.span(), Spanned::span);
        return Err(src.error(
            Some(at),
            &format!(
                "load increments below {:e} would not move the load factor (min_increment {min:e}: 1/steps / 1024 by default)",
                mpm_solver::MIN_LOAD_INCREMENT
            ),
        ));
    }
    let tolerance = check.positive(&s.tolerance, "solver `tolerance`")?;
    let max_iterations = check.at_least(&s.max_iterations, 1, "solver `max_iterations`")?;
    let defaults = NewtonOptions::default();
    let fraction = |value: &Option<Spanned<f64>>, default: f64, key: &str| {
        match value {
        None => Ok(default),
        Some(v) if (0.0..1.0).contains(v.get_ref()) => Ok(*v.get_ref()),
        Some(v) => Err(src.at(
            v,
            format!(
                "solver `{key}` is a fraction of the largest node's, in [0, 1) (0 disables the rule), got {}",
                v.get_ref()
            ),
        )),
    }
    };
    let weak_node_threshold = fraction(
        &s.weak_node_threshold,
        defaults.weak_node_threshold,
        "weak_node_threshold",
    )?;
    let weak_node_stiffness = fraction(
        &s.weak_node_stiffness,
        defaults.weak_node_stiffness,
        "weak_node_stiffness",
    )?;
    let ghost = ghost_penalty(s, src, grid)?;
    let linear = {
        let mut iterative = mpm_solver::IterativeOptions::default();
        if let Some(t) = &s.linear_tolerance {
            let t = check.positive(t, "solver `linear_tolerance`")?;
            if t >= 1.0 {
                return Err(src.at(
                    s.linear_tolerance.as_ref().map_or(&s.tolerance, |t| t),
                    "solver `linear_tolerance` must be below 1 (a relative residual)",
                ));
            }
            iterative.rel_tolerance = t;
        }
        match s.linear.get_ref() {
            LinearKind::Direct => mpm_solver::LinearChoice::Direct,
            // PETSc's solver replaces the iterative one at run time
            // (mpm-dispatch) and takes its tolerances.
            LinearKind::Iterative | LinearKind::Petsc(_) => {
                mpm_solver::LinearChoice::Iterative(iterative)
            }
            LinearKind::Auto => mpm_solver::LinearChoice::Auto {
                max_direct_dofs: s.max_direct_dofs.as_ref().map(|m| *m.get_ref()),
                iterative,
            },
        }
    };
    if let Some(t) = &s.linear_tolerance
        && *s.linear.get_ref() == LinearKind::Direct
    {
        return Err(src.at(
            t,
            "solver `linear_tolerance` applies to the iterative solvers (`linear = \"iterative\"`, `\"auto\"` or `{ petsc = ... }`) only",
        ));
    }
    if let Some(m) = &s.max_direct_dofs
        && *s.linear.get_ref() != LinearKind::Auto
    {
        return Err(src.at(
            m,
            "solver `max_direct_dofs` applies to `linear = \"auto\"` only",
        ));
    }
    Ok((
        LoadStepping { initial, max, min },
        NewtonOptions {
            tolerance,
            max_iterations,
            predictor: *s.predictor.get_ref(),
            first_tangent: (*s.first_tangent.get_ref()).into(),
            linear,
            weak_node_threshold,
            weak_node_stiffness,
            ghost,
            ..NewtonOptions::default()
        },
    ))
}

/// The PETSc request of `linear = { petsc = "..." }`, `None` for the
/// built-in solvers. PETSc itself checks the options when the solver is
/// built (an unknown method, an option no object reads); a program built
/// without PETSc refuses the request with the message located here.
///
/// # Errors
/// [`SceneError::Scene`] at `linear` when the options hold a NUL byte.
pub(super) fn petsc_request(
    s: &SolverSpec,
    src: &SceneSource,
) -> Result<Option<PetscRequest>, SceneError> {
    let LinearKind::Petsc(options) = s.linear.get_ref() else {
        return Ok(None);
    };
    if options.contains('\0') {
        return Err(src.at(
            &s.linear,
            "solver `linear`: PETSc options may not hold a NUL byte",
        ));
    }
    let without = src.at(
        &s.linear,
        "solver `linear = { petsc = ... }` needs an mpm built with PETSc: `cargo build --release -p mpm-cases --features petsc` (README, \"Distributed runs\")",
    );
    Ok(Some(PetscRequest {
        options: options.clone(),
        without_petsc: without.to_string(),
    }))
}

/// The ghost penalty of `s` (off unless `ghost_penalty` is given); `grid`:
/// the scene's mesh is a regular grid, whose cells' faces it acts on.
///
/// # Errors
/// [`SceneError::Scene`] at `ghost_penalty` or `ghost_fill`.
fn ghost_penalty(
    s: &SolverSpec,
    src: &SceneSource,
    grid: bool,
) -> Result<mpm_solver::GhostPenalty, SceneError> {
    Ok(match (&s.ghost_penalty, &s.ghost_fill) {
        (None, Some(f)) => {
            return Err(src.at(f, "solver `ghost_fill` applies with `ghost_penalty`"));
        }
        (None, None) => mpm_solver::GhostPenalty::OFF,
        (Some(g), fill) => {
            if !(g.get_ref().is_finite() && *g.get_ref() >= 0.0) {
                return Err(src.at(
                    g,
                    format!(
                        "solver `ghost_penalty` is a multiple of the law's 2μ, >= 0 (0 disables it), got {}",
                        g.get_ref()
                    ),
                ));
            }
            if *g.get_ref() > 0.0 && !grid {
                return Err(src.at(
                    g,
                    "solver `ghost_penalty` acts on the faces of a regular grid's cells ([mesh] kind = \"grid\")",
                ));
            }
            let fill = match fill {
                None => mpm_solver::GhostPenalty::OFF.fill,
                Some(f) if *f.get_ref() > 0.0 && *f.get_ref() <= 1.0 => *f.get_ref(),
                Some(f) => {
                    return Err(src.at(
                        f,
                        format!(
                            "solver `ghost_fill` is a fraction of a cell's volume in (0, 1], got {}",
                            f.get_ref()
                        ),
                    ));
                }
            };
            mpm_solver::GhostPenalty {
                factor: *g.get_ref(),
                fill,
            }
        }
    })
}
