//! Mailboxing (Amanatides & Woo 1987): a primitive that lies in several cells of a grid
//! or octree is tested once per ray. Each thread keeps one stamp per primitive; a query
//! takes a fresh stamp, and a primitive whose stamp is the query's has been tested.

use std::cell::RefCell;

#[derive(Default)]
pub struct Mailbox {
    query: u32,
    stamps: Vec<u32>,
}

thread_local! {
    /// A pool rather than one mailbox: structures nest (a grid of meshes, each with a
    /// grid of its own), and each level of a query needs its own stamps.
    static MAILBOXES: RefCell<Vec<Mailbox>> = const { RefCell::new(Vec::new()) };
}

impl Mailbox {
    /// Runs `f` with a mailbox of this thread, emptied for a new query over `prim_count`
    /// primitives.
    pub fn with<R>(prim_count: usize, f: impl FnOnce(&mut Mailbox) -> R) -> R {
        let mut m = MAILBOXES.with(|pool| pool.borrow_mut().pop()).unwrap_or_default();
        if m.stamps.len() < prim_count {
            m.stamps.resize(prim_count, 0);
        }
        m.query = m.query.wrapping_add(1);
        if m.query == 0 {
            // After 2³² queries the stamps would repeat: start afresh.
            m.stamps.fill(0);
            m.query = 1;
        }
        let r = f(&mut m);
        MAILBOXES.with(|pool| pool.borrow_mut().push(m));
        r
    }

    /// True the first time a primitive is seen in this query.
    #[inline(always)]
    pub fn first_visit(&mut self, prim: u32) -> bool {
        let s = &mut self.stamps[prim as usize];
        let first = *s != self.query;
        *s = self.query;
        first
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_primitive_once_per_query() {
        Mailbox::with(10, |m| {
            assert!(m.first_visit(3));
            assert!(!m.first_visit(3));
            assert!(m.first_visit(4));
        });
        Mailbox::with(10, |m| assert!(m.first_visit(3)));
        // A later query over more primitives grows the stamps.
        Mailbox::with(100, |m| assert!(m.first_visit(99)));
        // Queries nest (structures inside structures), each with its own stamps.
        Mailbox::with(10, |outer| {
            assert!(outer.first_visit(5));
            Mailbox::with(10, |inner| assert!(inner.first_visit(5)));
            assert!(!outer.first_visit(5));
        });
    }
}
