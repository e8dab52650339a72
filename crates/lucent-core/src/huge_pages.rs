//! Buffers of many megabytes (a BVH's references, nodes and packets; a film's sums)
//! backed by transparent huge pages where Linux gives them on request (`madvise`, the
//! common default): a 2 MB page faults in once instead of 512 times. Page faults were a
//! tenth of a large build's time (more with two threads, which wait on each other in the
//! kernel), and a few percent of a fast render's, whose film is fresh memory. Elsewhere,
//! and for small buffers, a plain vector.

/// Below this a buffer keeps ordinary pages (it would gain a few faults at most).
#[cfg(target_os = "linux")]
const MIN_BYTES: usize = 8 << 20;

/// An empty vector with room for `n` elements, its pages huge where that is possible.
pub fn vec_with_capacity<T>(n: usize) -> Vec<T> {
    let v = Vec::with_capacity(n);
    #[cfg(target_os = "linux")]
    advise_huge(&v);
    v
}

/// `n` copies of `value`, the pages huge where that is possible (see
/// [`vec_with_capacity`]).
pub fn vec_filled<T: Clone>(n: usize, value: T) -> Vec<T> {
    let mut v = vec_with_capacity(n);
    v.resize(n, value);
    v
}

#[cfg(target_os = "linux")]
fn advise_huge<T>(v: &Vec<T>) {
    const HUGE: usize = 2 << 20;
    let bytes = v.capacity() * std::mem::size_of::<T>();
    if bytes < MIN_BYTES {
        return;
    }
    // The whole huge pages inside the allocation.
    let start = v.as_ptr() as usize;
    let (first, end) = ((start + HUGE - 1) & !(HUGE - 1), (start + bytes) & !(HUGE - 1));
    if end > first {
        // SAFETY: the range lies inside the vector's allocation, which nothing has
        // touched yet; MADV_HUGEPAGE only changes how the kernel backs it (an error,
        // such as a kernel without huge pages, leaves it as it was).
        unsafe {
            libc::madvise(first as *mut libc::c_void, end - first, libc::MADV_HUGEPAGE);
        }
    }
}
