//! Whether standard output was closed when the program started. Rust's runtime opens /dev/null
//! in place of a closed standard stream before `main` runs, so output written there would be
//! lost without a word; the check must run before it, as a constructor.

use std::sync::atomic::{AtomicBool, Ordering};

/// Set before `main` if file descriptor 1 was not open.
static CLOSED: AtomicBool = AtomicBool::new(false);

#[allow(unsafe_code)]
mod probe {
    use std::ffi::c_int;

    /// `fcntl(2)`'s command that reads a descriptor's flags (fails with EBADF on a closed one).
    const F_GETFD: c_int = 1;

    unsafe extern "C" {
        fn fcntl(fd: c_int, cmd: c_int, ...) -> c_int;
    }

    // SAFETY: runs before main; it makes one system call on a descriptor number and stores a
    // flag, touching no state of the runtime.
    #[ctor::ctor(unsafe)]
    fn probe() {
        // SAFETY: F_GETFD takes no argument and only reads the descriptor table.
        let closed = unsafe { fcntl(1, F_GETFD) } == -1;
        super::CLOSED.store(closed, super::Ordering::Relaxed);
    }
}

/// True if standard output was closed when the program started.
pub fn was_closed() -> bool {
    CLOSED.load(Ordering::Relaxed)
}
