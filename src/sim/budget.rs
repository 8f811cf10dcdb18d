//! The memory budget of a stored motion.
//!
//! A motion is stored as its integration steps (dense output), each holding
//! the integrated vector at its ends and, for the adaptive method, its
//! stage derivatives: with tangents, 13 + 12 m numbers per body and stage.
//! A body spinning thousands of radians per second (the solver can drive
//! one there) or a step limit far below what the scene needs makes millions
//! of steps, and used to fill gigabytes before the run ended. Every run now
//! counts what it stores and stops with [`super::SimError::MotionTooLarge`]
//! past [`MAX_STORED_VALUES`], naming the body that stores the most.

/// Most numbers (f64) a simulated motion may store: 2²⁵, 256 MiB. The
/// shipped scenes store under 0.5 % of it (the spinning box, 10 s of
/// adaptive steps with six tangent columns, the most).
pub const MAX_STORED_VALUES: usize = 1 << 25;

/// What a running simulation has stored, per body.
#[derive(Debug, Clone, Default)]
pub(crate) struct Stored {
    per_body: Vec<usize>,
    total: usize,
}

impl Stored {
    pub fn new(bodies: usize) -> Stored {
        Stored {
            per_body: vec![0; bodies],
            total: 0,
        }
    }

    /// Body `i` stored `n` more numbers.
    pub fn add(&mut self, i: usize, n: usize) {
        self.per_body[i] += n;
        self.total += n;
    }

    /// Body `i` dropped `n` of its numbers (steps cut at an event).
    pub fn remove(&mut self, i: usize, n: usize) {
        let n = n.min(self.per_body[i]);
        self.per_body[i] -= n;
        self.total -= n;
    }

    /// The body storing the most, if the budget is exceeded.
    pub fn over_budget(&self) -> Option<usize> {
        if self.total <= MAX_STORED_VALUES {
            return None;
        }
        (0..self.per_body.len()).max_by_key(|&i| self.per_body[i])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_budget_names_the_body_that_stores_most() {
        let mut s = Stored::new(3);
        s.add(0, 10);
        s.add(2, MAX_STORED_VALUES - 10);
        assert_eq!(s.over_budget(), None);
        s.add(1, 1);
        assert_eq!(s.over_budget(), Some(2));
        s.remove(2, 5);
        assert_eq!(s.over_budget(), None);
        s.add(0, 4);
        assert_eq!(s.over_budget(), None, "exactly the budget is within it");
        s.add(0, 1);
        assert_eq!(s.over_budget(), Some(2));
    }
}
