//! What a step could not keep of the project's promises, said at the step where it happened
//! (docs/physics.md §3.5): a surface that ended a step through a collider, through itself
//! where self-contact skips, or through itself or another surface after an explicit step
//! too large for its contacts. The simulation keeps the first notice of each kind for each
//! collider and each surface and counts the steps of the rest, so a long run says it once,
//! when it begins, and how often at its end.

use crate::integrator::Integrator;
use crate::number::Approx;
use std::fmt;

/// A surface (a cloth's edge or triangle) that passes through a collider, through itself
/// or through another surface, after a step.
#[derive(Clone, Debug, PartialEq)]
pub struct Notice {
    /// The step after which it was found (1 for the first step).
    pub step: u64,
    /// The simulated time then, seconds.
    pub time: f64,
    /// What the surface passes through.
    pub through: Through,
    /// A particle of the edge or triangle that meets it (for a surface through itself,
    /// an end of the edge that passes).
    pub particle: usize,
    /// Why the integrator could not keep it out.
    pub cause: Cause,
}

/// What a surface passed through.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Through {
    /// A collider, by its index in the model.
    Collider(usize),
    /// The surface itself (its index among the model's surfaces): one of its triangles
    /// through another of it.
    Itself(usize),
    /// Two surfaces through each other (their indices among the model's surfaces, lower
    /// first): [`Notice::particle`] is on the first.
    Surfaces(usize, usize),
}

/// Why a step left a surface through a collider or a surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Cause {
    /// The integrator's contacts come after its step (every integrator but block descent),
    /// and the step moved a particle `moved` metres relative to the collider, more than half
    /// the thinnest contact thickness `thickness`: a surface can pass a collider's edge, or
    /// a thin part of it, between two looks.
    LargeStep {
        /// The integrator that took the step.
        integrator: Integrator,
        /// The step's largest move of a surface particle, metres.
        moved: f64,
        /// The thinnest contact thickness of the surfaces, metres.
        thickness: f64,
    },
    /// Block descent with a moving collider: a pinned particle lies in the collider's path,
    /// where nothing can move it aside.
    Pinned,
    /// Block descent with a moving collider: the collider closed on a particle squeezed
    /// between it and something else faster than `parts` parts of the step could follow
    /// (docs/physics.md §4.1, "A moving collider").
    Squeezed {
        /// The parts the step was taken in.
        parts: u32,
    },
    /// The surface folded through itself where self-contact skips its pairs: a crease
    /// tighter than the pairs its own structure was taken to hold apart
    /// (docs/physics.md §4.1, "What self-contact skips").
    Crease {
        /// The skipped pairs' reach at rest, metres.
        reach: f64,
        /// The integrator that took the step.
        integrator: Integrator,
    },
    /// The integrator's contacts come after its step, and the step moved a surface particle
    /// `moved` metres relative to the surfaces' shared motion, more than half the thinnest
    /// thickness of surfaces that touch, `thickness`: two layers can close by more than
    /// the thickness, and pass through each other, between two looks.
    Layers {
        /// The integrator that took the step.
        integrator: Integrator,
        /// The step's largest move of a surface particle relative to the surfaces' mean
        /// move, metres.
        moved: f64,
        /// The thinnest contact thickness of the surfaces that touch, metres.
        thickness: f64,
    },
}

impl Cause {
    /// Two notices of one kind for one collider are said once.
    pub(crate) fn kind(&self) -> u8 {
        match self {
            Self::LargeStep { .. } => 0,
            Self::Pinned => 1,
            Self::Squeezed { .. } => 2,
            Self::Crease { .. } => 3,
            Self::Layers { .. } => 4,
        }
    }
}

impl fmt::Display for Cause {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::LargeStep {
                integrator,
                moved,
                thickness,
            } => write!(
                f,
                "{integrator} resolves contacts after its step, and this step moved a particle \
                 {} mm, more than half the contact thickness of {} mm, so a surface can pass a \
                 collider's edge or a thin part of it between two looks; take a smaller dt \
                 (hooke check says which), or `--integrator vbd`, whose steps keep every \
                 surface out at any dt",
                Approx(moved * 1e3),
                Approx(thickness * 1e3),
            ),
            Self::Pinned => f.write_str(
                "a pinned particle lies in the moving collider's path and nothing can move it \
                 aside, so no integrator can keep the surface out there; key the collider or \
                 the pins around each other",
            ),
            Self::Squeezed { parts } => write!(
                f,
                "the moving collider squeezed a particle against something that held it, \
                 faster than block descent's {parts} parts of the step could follow (each part \
                 lets the collider close at most half the gap, down to a part of dt/{}); give \
                 the body room to move aside, or key the collider slower",
                crate::simulation::swept::MOST_PARTS
            ),
            Self::Crease { reach, integrator } => write!(
                f,
                "it folded tighter than the pairs self-contact skips ({integrator} skips those \
                 within {} mm of each other at rest and near along the surface's edges, which \
                 only the cloth's own springs hold apart: docs/physics.md §4.1), and an edge \
                 passed through a triangle beside it; a thinner `thickness` narrows the \
                 skipped pairs ({} times it), so that the crease is kept open",
                Approx(reach * 1e3),
                if integrator.solves_contacts() { 4 } else { 2 },
            ),
            Self::Layers {
                integrator,
                moved,
                thickness,
            } => write!(
                f,
                "{integrator} resolves contacts after its step, and this step moved a surface \
                 particle {} mm relative to the surfaces' shared motion, more than half the \
                 contact thickness of {} mm, so two layers can close by more than the \
                 thickness and pass through each other between two looks; take a smaller dt \
                 (hooke check says which), or `--integrator vbd`, whose steps keep surfaces \
                 apart at any dt",
                Approx(moved * 1e3),
                Approx(thickness * 1e3),
            ),
        }
    }
}

/// The notices of a run: the new ones not yet taken, and per (what was passed through,
/// kind) the first notice and the steps it happened in.
#[derive(Clone, Debug, Default)]
pub(crate) struct Notices {
    fresh: Vec<Notice>,
    tally: Vec<(Notice, u64)>,
}

impl Notices {
    /// Records `n`: new when what it passed through has had none of its kind.
    pub(crate) fn record(&mut self, n: Notice) {
        let key = (n.through, n.cause.kind());
        if let Some((_, count)) = self
            .tally
            .iter_mut()
            .find(|(first, _)| (first.through, first.cause.kind()) == key)
        {
            *count += 1;
        } else {
            self.tally.push((n.clone(), 1));
            self.fresh.push(n);
        }
    }

    /// The notices not yet taken.
    pub(crate) fn take(&mut self) -> Vec<Notice> {
        std::mem::take(&mut self.fresh)
    }

    /// Each kind's first notice and the steps it happened in.
    pub(crate) fn tally(&self) -> &[(Notice, u64)] {
        &self.tally
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_kind_is_said_once_per_collider_and_counted() {
        let at = |step, collider, cause| Notice {
            step,
            time: step as f64,
            through: Through::Collider(collider),
            particle: 0,
            cause,
        };
        let mut n = Notices::default();
        n.record(at(3, 1, Cause::Pinned));
        n.record(at(4, 1, Cause::Pinned));
        n.record(at(4, 2, Cause::Pinned));
        n.record(at(5, 1, Cause::Squeezed { parts: 9 }));
        let crease = Cause::Crease {
            reach: 0.02,
            integrator: Integrator::Vbd,
        };
        let folded = |step| Notice {
            through: Through::Itself(1),
            ..at(step, 1, crease)
        };
        n.record(folded(6));
        n.record(folded(7));
        let fresh = n.take();
        assert_eq!(
            fresh.iter().map(|n| n.step).collect::<Vec<_>>(),
            [3, 4, 5, 6]
        );
        assert!(n.take().is_empty());
        assert_eq!(n.tally()[0].1, 2);
        assert_eq!(
            n.tally()[3].1,
            2,
            "a surface through itself is counted apart"
        );
        assert!(crease.to_string().contains("within 20 mm"));
        assert!(Cause::Squeezed { parts: 9 }.to_string().contains("9 parts"));
    }
}
