//! Feature alignment only: this crate has no code. Its dependencies turn
//! on, in every build that includes it, the union of the features the
//! workspace's builds turn on in shared crates (see its `Cargo.toml`).
