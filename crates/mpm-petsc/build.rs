//! Finds PETSc with pkg-config (Debian's `petsc-dev`: PETSc 3.18, real
//! double scalars, 32-bit indices) and generates the declarations of the
//! KSP, Mat, Vec and options calls the wrapper uses.

use std::env;
use std::path::PathBuf;

fn main() {
    let petsc = match pkg_config::Config::new()
        .atleast_version("3.18")
        .probe("petsc")
    {
        Ok(lib) => lib,
        Err(e) => {
            eprintln!(
                "mpm-petsc needs PETSc (>= 3.18) found by pkg-config: on Debian \
                 `apt-get install petsc-dev libopenmpi-dev libclang-dev`.\n{e}"
            );
            std::process::exit(1);
        }
    };
    // MPI's headers (petscsys.h includes mpi.h) and library (the wrapper
    // asks MPI for the number of processes).
    let mpi = pkg_config::Config::new()
        .probe("ompi-c")
        .or_else(|_| pkg_config::Config::new().probe("mpi"));
    let mut builder = bindgen::Builder::default()
        .header("wrapper.h")
        .allowlist_function("(KSP|PC|Mat|Vec|Petsc)\\w*|MPI_Comm_size")
        .allowlist_var("PETSC_\\w*|(KSP|PC|MAT|VEC|INSERT|ADD|SCATTER)\\w*")
        .allowlist_type("(KSP|PC|Mat|Vec|Petsc|Insert|Scatter)\\w*")
        .opaque_type("_p_\\w*")
        .derive_debug(false)
        .layout_tests(false)
        .prepend_enum_name(false)
        .generate_comments(false);
    for dir in petsc
        .include_paths
        .iter()
        .chain(mpi.iter().flat_map(|m| m.include_paths.iter()))
    {
        builder = builder.clang_arg(format!("-I{}", dir.display()));
    }
    let bindings = match builder.generate() {
        Ok(b) => b,
        Err(e) => {
            eprintln!("bindgen over PETSc's headers failed (libclang-dev installed?): {e}");
            std::process::exit(1);
        }
    };
    let out = PathBuf::from(env::var("OUT_DIR").expect("cargo sets OUT_DIR"));
    if let Err(e) = bindings.write_to_file(out.join("petsc.rs")) {
        eprintln!("cannot write the PETSc bindings: {e}");
        std::process::exit(1);
    }
    println!("cargo:rerun-if-changed=wrapper.h");
}
