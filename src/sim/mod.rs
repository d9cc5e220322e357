//! Material -> membrane: meshes, spring models, loads and solvers.
