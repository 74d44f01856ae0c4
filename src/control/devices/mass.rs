//! The tuned mass damper and active mass driver: a mass added to a structure.

use crate::hysteresis::positive;
use crate::linalg::Rows;
use crate::{Error, Param};

/// A structure of `M` degrees of freedom with an added mass: its `M`, `C`, `K` (row-major,
/// `f64`, SI) and the input vector `b` of the force between the added mass and its floor.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MassDamper<const M: usize> {
    /// The mass matrix (kg).
    pub mass: Rows<M>,
    /// The damping matrix (N·s/m).
    pub damping: Rows<M>,
    /// The stiffness matrix (N/m).
    pub stiffness: Rows<M>,
    /// `b = e_{M−1} − e_floor`: a force `F` pushing the added mass (and back on its
    /// floor) is the load `b F`.
    pub force: [f64; M],
}

/// A tuned mass damper or active mass driver: the structure `m`, `c`, `k` (`N` degrees of
/// freedom, SI, relative to the ground) with a mass `mass` (kg, finite, `> 0`) added on
/// degree of freedom `floor` through a spring `stiffness` (N/m) and a dashpot `damping`
/// (N·s/m), both finite and `≥ 0`, as in the control–structure-interaction literature
/// (Dyke, Spencer, Quast & Sain 1995, "Role of control-structure interaction in protective
/// system design"). The added mass is degree of freedom `M − 1 = N` (its displacement
/// relative to the ground, like the floors'), so base excitation is `p = −M ι a_g` with
/// `ι` all ones.
///
/// An active mass driver's actuator is a [`ForceActuator`](super::ForceActuator) at
/// [`Link::Between`](super::Link::Between)`(N, floor)` of a
/// [`Coupled`](super::Coupled) model of the augmented structure (its first-order lag the
/// actuator's dynamics; the servo-hydraulic velocity feedback of a real driver is not
/// modelled); a tuned mass damper needs none (stiffness and damping tuned, e.g. by Den
/// Hartog's rules).
///
/// Errors: [`Error::StateSizeMismatch`] (`M ≠ N + 1`), [`Error::InvalidParameter`]`(`
/// [`Param::Device`]`)` (`floor ≥ N`), [`Error::InvalidMaterial`]`(`[`Param::Device`]`)`
/// (`mass`, `stiffness` or `damping` out of range), [`Error::NonFiniteInput`] (an entry of
/// `m`, `c`, `k` not finite). Cost: O(M²).
pub fn mass_damper<const N: usize, const M: usize>(
    m: &Rows<N>,
    c: &Rows<N>,
    k: &Rows<N>,
    floor: usize,
    mass: f64,
    stiffness: f64,
    damping: f64,
) -> Result<MassDamper<M>, Error> {
    if M != N + 1 {
        return Err(Error::StateSizeMismatch);
    }
    if floor >= N {
        return Err(Error::InvalidParameter(Param::Device));
    }
    let nonneg = |x: f64| x.is_finite() && x >= 0.0;
    if !(positive(mass) && nonneg(stiffness) && nonneg(damping)) {
        return Err(Error::InvalidMaterial(Param::Device));
    }
    if !m.iter().chain(c).chain(k).flatten().all(|x| x.is_finite()) {
        return Err(Error::NonFiniteInput);
    }
    // The structure's blocks, then the added element between `floor` and `N`.
    let embed = |a: &Rows<N>| -> Rows<M> {
        core::array::from_fn(|i| {
            core::array::from_fn(|j| if i < N && j < N { a[i][j] } else { 0.0 })
        })
    };
    let link = |a: &mut Rows<M>, x: f64| {
        a[floor][floor] += x;
        a[N][N] += x;
        a[floor][N] -= x;
        a[N][floor] -= x;
    };
    let mut out = MassDamper {
        mass: embed(m),
        damping: embed(c),
        stiffness: embed(k),
        force: [0.0; M],
    };
    out.mass[N][N] = mass;
    link(&mut out.stiffness, stiffness);
    link(&mut out.damping, damping);
    out.force[N] = 1.0;
    out.force[floor] = -1.0;
    Ok(out)
}
