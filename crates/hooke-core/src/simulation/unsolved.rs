//! Steps that a large-step integrator ended at its iteration budget before its stopping
//! rule was met (docs/physics.md §4.1, "Stopping rule and accuracy"; a capped step): counted,
//! with the first of them, so that a run can say how many of its steps are not solved to the
//! tolerance it asked for. Each such step still keeps its bounds; what it leaves is motion
//! short of the step's equations, which a bench measures (`hooke bench scene --residual`).

/// The steps a run ended at its solver's budget so far.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Unsolved {
    /// How many.
    pub steps: u64,
    /// The first of them (1 for the first step; it ends at `first · dt`).
    pub first: Option<u64>,
}

impl Unsolved {
    /// Counts step `step`.
    pub(crate) fn record(&mut self, step: u64) {
        self.steps += 1;
        self.first.get_or_insert(step);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_is_kept_and_every_one_counted() {
        let mut u = Unsolved::default();
        u.record(3);
        u.record(7);
        assert_eq!(
            u,
            Unsolved {
                steps: 2,
                first: Some(3)
            }
        );
    }
}
