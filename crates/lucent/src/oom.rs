//! A failed allocation ends the run like any other lack of resources — exit code 2 and a
//! message — instead of Rust's default abort. The memory budget
//! (`lucent_io::resources::budget`) refuses what it can foresee; this is for what it
//! cannot. Nothing here may allocate: the message is put together on the stack, and the
//! temporary output file is removed by a list prepared when it was made.

use std::alloc::{GlobalAlloc, Layout, System};

use lucent_io::resources::output::remove_temporary_files;

pub struct ExitOnFailure;

// SAFETY: every call is passed to the system allocator unchanged; a null result ends
// the process instead of being returned.
unsafe impl GlobalAlloc for ExitOnFailure {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = System.alloc(layout);
        if p.is_null() {
            fail(layout.size());
        }
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let p = System.alloc_zeroed(layout);
        if p.is_null() {
            fail(layout.size());
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let p = System.realloc(ptr, layout, new_size);
        if p.is_null() {
            fail(new_size);
        }
        p
    }
}

/// Says which allocation failed, removes temporary files and exits with code 2.
fn fail(size: usize) -> ! {
    let mut msg = [0u8; 160];
    let mut n = 0;
    let mut put = |bytes: &[u8]| {
        for &b in bytes {
            if n < msg.len() {
                msg[n] = b;
                n += 1;
            }
        }
    };
    put(b"\nlucent: error: out of memory: an allocation of ");
    let mut digits = [0u8; 20];
    let mut k = digits.len();
    let mut v = size;
    loop {
        k -= 1;
        digits[k] = b'0' + (v % 10) as u8;
        v /= 10;
        if v == 0 {
            break;
        }
    }
    put(&digits[k..]);
    put(b" bytes failed (a lower --memory-limit refuses such scenes earlier)\n");
    remove_temporary_files();
    // SAFETY: writing a stack buffer to standard error and ending the process; neither
    // allocates.
    unsafe {
        libc::write(2, msg.as_ptr().cast(), n);
        libc::_exit(2);
    }
}
