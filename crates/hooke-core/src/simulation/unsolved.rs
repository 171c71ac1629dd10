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
    /// The first of them (1 for the first step) and the simulated time at its end, seconds.
    pub first: Option<(u64, f64)>,
}

impl Unsolved {
    /// Counts step `step`, ended at `time`.
    pub(crate) fn record(&mut self, step: u64, time: f64) {
        self.steps += 1;
        self.first.get_or_insert((step, time));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_is_kept_and_every_one_counted() {
        let mut u = Unsolved::default();
        u.record(3, 0.05);
        u.record(7, 0.1);
        assert_eq!(
            u,
            Unsolved {
                steps: 2,
                first: Some((3, 0.05))
            }
        );
    }
}
