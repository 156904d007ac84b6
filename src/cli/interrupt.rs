//! Ctrl-C during a solve: the first press asks the solver to stop (iterative solvers
//! return their best map so far, which the command still writes); a second press ends
//! the program at once.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};

static FLAG: OnceLock<Arc<AtomicBool>> = OnceLock::new();

/// The flag Ctrl-C raises, with the handler installed on first use.
pub fn cancel_flag() -> Arc<AtomicBool> {
    let flag = FLAG.get_or_init(|| {
        install();
        Arc::new(AtomicBool::new(false))
    });
    Arc::clone(flag)
}

/// Whether Ctrl-C was pressed.
pub fn interrupted() -> bool {
    FLAG.get().is_some_and(|f| f.load(Ordering::Relaxed))
}

#[cfg(unix)]
extern "C" fn on_interrupt(_: libc::c_int) {
    // Only async-signal-safe work here: an atomic store and `signal`.
    if let Some(flag) = FLAG.get() {
        flag.store(true, Ordering::Relaxed);
    }
    // SAFETY: restoring the default action, so that a second Ctrl-C terminates.
    unsafe {
        libc::signal(libc::SIGINT, libc::SIG_DFL);
    }
}

#[cfg(unix)]
fn install() {
    let handler: extern "C" fn(libc::c_int) = on_interrupt;
    // SAFETY: the handler only stores to an atomic and calls `signal`.
    unsafe {
        libc::signal(libc::SIGINT, handler as libc::sighandler_t);
    }
}

#[cfg(not(unix))]
fn install() {}
