//! The gap check of the friction walls: which wall nodes a body touches.
//!
//! Bardenhagen, Brackbill & Sulsky (2000) put two bodies in contact at
//! every node where both have mass and approach each other. Against a
//! wall that is every node of the face within the basis's support of a
//! point, one to two cells beyond where the body actually touches: a disk
//! on the floor then rests on a flat as wide as its support reaches, the
//! nodes ahead of the contact are stopped as they come down, and the disk
//! slides instead of rolling (docs/src/theory/contact.md, "The rolling
//! cylinder"). Contact algorithms therefore check the gap before they act
//! (the "displacement check" of Lemiale et al. 2010, Nairn 2013; Nairn,
//! Bardenhagen & Smith 2018, *Comput. Part. Mech.* 5, 285–296, review
//! them): a gap-checked wall acts on a node only where a point touches it
//! over that node.
//!
//! A point is taken as the square (cube) of side $l_p = V_p^{1/D}$ centred
//! on it, $V_p$ its current volume. It touches a wall when its face
//! reaches within [`TOUCH_TOLERANCE`]$\,l_p$ of the wall's plane, and it
//! lies over the nodes whose tributary cell (a node spacing $h$ wide,
//! centred on the node) its square overlaps along the wall: the nodes at
//! tangential distance at most $(h + l_p)/2$.

use nalgebra::SVector;

use super::fixities::FrictionWall;

/// How close (as a fraction of the point's size $l_p$) a point's face
/// must come to a wall to touch it: points laid on a lattice whose face
/// lies on the wall touch it up to round-off, and a body pressed on the
/// wall by its weight sinks into it by its elastic compression; a tenth
/// of the point takes both and leaves a body that lifts off by more free.
pub const TOUCH_TOLERANCE: f64 = 0.1;

/// The regular lattice of the nodes: node ids run along axis 0 fastest.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lattice<const D: usize> {
    /// Position of node 0.
    pub origin: SVector<f64, D>,
    /// Node spacing per axis.
    pub spacing: SVector<f64, D>,
    /// Nodes per axis.
    pub nodes: [usize; D],
}

/// One face of gap-checked walls: its axis, side, plane and index along
/// the axis.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Face {
    axis: usize,
    upper: bool,
    plane: f64,
    index: usize,
}

/// The touched nodes of the gap-checked walls, marked anew every step
/// ([`WallTouch::mark`]); empty when no wall is gap-checked.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct WallTouch<const D: usize> {
    faces: Vec<Face>,
    lattice: Option<Lattice<D>>,
    /// One flag per node of the mesh.
    touched: Vec<bool>,
    /// The gap-checked wall nodes (cleared before marking).
    nodes: Vec<usize>,
}

impl<const D: usize> WallTouch<D> {
    /// The faces of the gap-checked `walls` on `lattice` (the walls'
    /// nodes and axes already checked against it).
    pub fn new(walls: &[FrictionWall], lattice: Lattice<D>) -> Self {
        let mut faces: Vec<Face> = Vec::new();
        let mut nodes = Vec::new();
        for w in walls.iter().filter(|w| w.gap_check) {
            nodes.push(w.node);
            if faces.iter().any(|f| (f.axis, f.upper) == (w.axis, w.upper)) {
                continue;
            }
            let index = if w.upper {
                lattice.nodes[w.axis] - 1
            } else {
                0
            };
            faces.push(Face {
                axis: w.axis,
                upper: w.upper,
                plane: lattice.origin[w.axis] + index as f64 * lattice.spacing[w.axis],
                index,
            });
        }
        if faces.is_empty() {
            return Self::default();
        }
        let count = lattice.nodes.iter().product();
        Self {
            faces,
            lattice: Some(lattice),
            touched: vec![false; count],
            nodes,
        }
    }

    /// Whether any wall is gap-checked.
    pub fn is_active(&self) -> bool {
        !self.faces.is_empty()
    }

    /// Marks the wall nodes the points at `position` with volumes
    /// `volume` touch, or reach over the step `dt` at their velocity
    /// `velocity` (a point approaching the wall touches it when its gap
    /// is within the tolerance plus the distance it approaches by in one
    /// step, so that a fast body cannot jump past the tolerance band and
    /// through the wall), after clearing the previous step's marks.
    pub fn mark(
        &mut self,
        position: &[SVector<f64, D>],
        velocity: &[SVector<f64, D>],
        volume: &[f64],
        dt: f64,
    ) {
        let Some(lattice) = self.lattice else {
            return;
        };
        for &n in &self.nodes {
            self.touched[n] = false;
        }
        for ((x, u), &v) in position.iter().zip(velocity).zip(volume) {
            let size = v.max(0.0).powf(1.0 / D as f64);
            for face in &self.faces {
                let (depth, approach) = if face.upper {
                    (face.plane - x[face.axis], u[face.axis])
                } else {
                    (x[face.axis] - face.plane, -u[face.axis])
                };
                let reach = TOUCH_TOLERANCE * size + approach.max(0.0) * dt;
                if depth - 0.5 * size <= reach {
                    mark_over(&lattice, face, x, size, &mut self.touched);
                }
            }
        }
    }

    /// The flags per node ([`super::grid_update::friction_walls`] reads
    /// them for the gap-checked walls); empty when none is.
    pub fn touched(&self) -> &[bool] {
        &self.touched
    }
}

/// Marks the nodes of `face` whose tributary cells the square of side
/// `size` at `x` overlaps along the face.
fn mark_over<const D: usize>(
    lattice: &Lattice<D>,
    face: &Face,
    x: &SVector<f64, D>,
    size: f64,
    touched: &mut [bool],
) {
    let mut lo = [0usize; D];
    let mut hi = [0usize; D];
    for c in 0..D {
        if c == face.axis {
            (lo[c], hi[c]) = (face.index, face.index);
            continue;
        }
        let (h, last) = (lattice.spacing[c], lattice.nodes[c] as f64 - 1.0);
        let reach = 0.5 * (h + size);
        let from = ((x[c] - reach - lattice.origin[c]) / h)
            .ceil()
            .clamp(0.0, last);
        let to = ((x[c] + reach - lattice.origin[c]) / h)
            .floor()
            .clamp(0.0, last);
        if from.is_nan() || to.is_nan() || from > to {
            return;
        }
        // Both within [0, last]: exact small integers.
        (lo[c], hi[c]) = (from as usize, to as usize);
    }
    let mut index = lo;
    loop {
        let mut node = 0;
        for c in (0..D).rev() {
            node = node * lattice.nodes[c] + index[c];
        }
        if let Some(flag) = touched.get_mut(node) {
            *flag = true;
        }
        let Some(c) = (0..D).find(|&c| index[c] < hi[c]) else {
            return;
        };
        index[c] += 1;
        index[..c].copy_from_slice(&lo[..c]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::explicit::VelocityFixities;

    /// A 4 × 3 node lattice of spacing 1 with a gap-checked floor (y_min).
    fn floor() -> WallTouch<2> {
        let mut f = VelocityFixities::new();
        f.friction_gap_checked(0..4, 1, false, 0.3);
        f.finish();
        WallTouch::new(
            f.walls(),
            Lattice {
                origin: SVector::zeros(),
                spacing: SVector::from([1.0, 1.0]),
                nodes: [4, 3],
            },
        )
    }

    /// A point of size 0.5 whose face is on the floor touches the nodes
    /// its square overlaps (x = 1.3: tributaries [0.5, 1.5] and [1.5,
    /// 2.5] reach to 1.3 ± 0.75); lifted by more than a tenth of its size
    /// it touches none; the marks are cleared each step.
    #[test]
    fn a_point_touches_the_nodes_under_it_only_when_its_face_reaches_the_wall() {
        let mut touch = floor();
        let volume = [0.25];
        touch.mark(
            &[SVector::from([1.3, 0.25])],
            &[SVector::zeros()],
            &volume,
            0.0,
        );
        assert_eq!(&touch.touched()[..4], &[false, true, true, false]);
        assert!(touch.touched()[4..].iter().all(|t| !t));
        touch.mark(
            &[SVector::from([1.3, 0.25 + 0.049])],
            &[SVector::zeros()],
            &volume,
            0.0,
        );
        assert_eq!(&touch.touched()[..4], &[false, true, true, false]);
        touch.mark(
            &[SVector::from([1.3, 0.25 + 0.051])],
            &[SVector::zeros()],
            &volume,
            0.0,
        );
        assert!(touch.touched().iter().all(|t| !t));
        touch.mark(
            &[SVector::from([3.0, 0.2])],
            &[SVector::zeros()],
            &volume,
            0.0,
        );
        assert_eq!(&touch.touched()[..4], &[false, false, false, true]);
    }

    /// A point that approaches the wall touches it once its gap is within
    /// the tolerance plus one step's approach: lifted 0.2 above the band
    /// and falling at 1 m/s, it touches with a step of 0.25 s, not with
    /// 0.15 s, nor when it rises at the same speed.
    #[test]
    fn an_approaching_point_touches_one_step_ahead() {
        let mut touch = floor();
        let (x, volume) = ([SVector::from([1.3, 0.25 + 0.05 + 0.2])], [0.25]);
        let down = [SVector::from([0.0, -1.0])];
        touch.mark(&x, &down, &volume, 0.25);
        assert_eq!(&touch.touched()[..4], &[false, true, true, false]);
        touch.mark(&x, &down, &volume, 0.15);
        assert!(touch.touched().iter().all(|t| !t));
        touch.mark(&x, &[SVector::from([0.0, 1.0])], &volume, 0.25);
        assert!(touch.touched().iter().all(|t| !t));
    }

    /// In 3D on the upper x face the marked nodes are a patch of the face;
    /// walls that are not gap-checked make no faces.
    #[test]
    fn a_patch_of_a_3d_face_is_marked_and_plain_walls_are_not_checked() {
        let lattice = Lattice {
            origin: SVector::zeros(),
            spacing: SVector::from([1.0, 1.0, 1.0]),
            nodes: [3, 4, 4],
        };
        let mut f = VelocityFixities::new();
        f.friction([2, 5], 0, true, 0.3);
        f.finish();
        assert!(!WallTouch::new(f.walls(), lattice).is_active());
        f.friction_gap_checked((0..16).map(|k| 2 + 3 * k), 0, true, 0.3);
        f.finish();
        let mut touch = WallTouch::new(f.walls(), lattice);
        assert!(touch.is_active());
        touch.mark(
            &[SVector::from([1.5, 1.6, 2.2])],
            &[SVector::zeros()],
            &[1.0],
            0.0,
        );
        let marked: Vec<usize> = (0..48).filter(|&n| touch.touched()[n]).collect();
        // y in {1, 2}, z in {2, 3}: 1.6 ± 1 and 2.2 ± 1 rounded inwards.
        let node = |y: usize, z: usize| 2 + 3 * (y + 4 * z);
        assert_eq!(marked, vec![node(1, 2), node(2, 2), node(1, 3), node(2, 3)]);
    }
}
