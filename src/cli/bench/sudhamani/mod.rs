//! Sudhamani & Merriliance's (2019) experiments, with every parameter it leaves out stated, and
//! the sudden pressure step on the disc.
//!
//! The paper fixes a square mesh on its left edge and loads it "at the middle" or
//! "at the corner" with forces in N/m, and reports the computation time
//! against the number of points (200-4000), the time step of explicit Euler,
//! implicit Euler and Verlet, and a "deformation error" against the force
//! (0-10 N/m). It gives no size, modulus, thickness, density, damping, step,
//! simulated time or tolerance. bulge's choices ([`SheetSetup::default`]):
//!
//! * a square of 0.1 m, thickness 1 mm, E = 50 kPa, nu = 0.45, density
//!   1060 kg/m^3 (soft tissue), Van Gelder springs (Sudhamani & Merriliance's springs are linear;
//!   Van Gelder's eq 1 sets their stiffness from E and nu). Sudhamani & Merriliance's liver
//!   modulus, 3.5 kPa, moves the loaded node 21-24 mm under 10 N/m at 200
//!   points (more than three mesh spacings): the point load then inverts
//!   triangles on fine meshes and the spring lattice has several equilibria
//!   (Newton and dynamic relaxation found two 4 % apart at 1000 points).
//!   50 kPa keeps the largest load's displacement near one spacing;
//! * the load is in the plane of the sheet, along -y, on the node at the
//!   middle (or the corner) of the free edge x = L. Its N/m is read as the 2D
//!   convention of a plane model: force per unit thickness, so the nodal force
//!   is `q t` and the displacement scales as `q / E` (10 N/m / 3.5 kPa =
//!   2.9 mm at 3.5 kPa, the size of Sudhamani & Merriliance's "errors"). The nodes are held in the plane
//!   z = 0 (a flat membrane has no stiffness out of its plane);
//! * damping: 0.1 of each spring's critical value;
//! * the static reference: Newton (sparse LU) to a residual of 1e-10 of the
//!   load.
//!
//! * [`tables`]: the three experiments on the sheet;
//! * [`markdown`]: their tables in `sudhamani-merriliance.md`;
//! * [`disc`]: the bubble disc and its sudden pressure step.

mod disc;
mod markdown;
mod sheet;
mod tables;

pub use disc::{bubble_disc, bubble_specimen};
pub use markdown::markdown;

pub use sheet::*;
