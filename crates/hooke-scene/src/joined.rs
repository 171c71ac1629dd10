//! Items joined into sets (union–find), each set named by its lowest item, so that what is
//! joined does not depend on the order of the joins: welded vertices, a body's pieces.

/// Sets of the items `0..n`, each item at first alone.
pub(crate) struct Joined {
    parent: Vec<u32>,
}

impl Joined {
    /// `n` items, each its own set.
    pub(crate) fn new(n: usize) -> Self {
        Self {
            parent: (0..n as u32).collect(),
        }
    }

    /// The lowest item of `i`'s set.
    pub(crate) fn root(&mut self, mut i: u32) -> u32 {
        while self.parent[i as usize] != i {
            let up = self.parent[self.parent[i as usize] as usize];
            self.parent[i as usize] = up;
            i = up;
        }
        i
    }

    /// Joins the sets of `a` and `b`.
    pub(crate) fn join(&mut self, a: u32, b: u32) {
        let (a, b) = (self.root(a), self.root(b));
        self.parent[a.max(b) as usize] = a.min(b);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_set_is_named_by_its_lowest_item_whatever_the_order_of_joins() {
        let mut sets = Joined::new(6);
        sets.join(5, 3);
        sets.join(3, 4);
        sets.join(4, 1);
        let roots: Vec<u32> = (0..6).map(|i| sets.root(i)).collect();
        assert_eq!(roots, [0, 1, 2, 1, 1, 1]);
    }
}
