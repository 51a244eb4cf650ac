//! No build step: the build-dependencies only align host-side features.
fn main() {}
