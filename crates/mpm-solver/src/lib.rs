//! Generic material point solvers.
//!
//! This crate will hold the plug-point traits `Formulation` (updated
//! Lagrangian / previously converged, Coombs et al. 2020 §3 and §5),
//! `LockingTreatment` (none / F-bar / F-patch / cell-averaged dilatation)
//! and `DomainUpdater` (the GIMP domain-update rules, Coombs et al. 2020
//! §6.4), and the solvers composed from them: an implicit Newton–Raphson
//! solver for quasi-static problems and an explicit dynamic solver. The
//! solvers depend on traits only, never on a concrete implementation.
