//! The `beltrami` command-line program.

mod cli;

#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    // Printing into a closed pipe (`beltrami info mesh.obj | head`) should end the
    // program quietly, as other command-line tools do, not panic.
    #[cfg(unix)]
    // SAFETY: restoring the default action of SIGPIPE before any thread starts.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    // A write beyond the file-size limit (`ulimit -f`) should fail with EFBIG, so that
    // the atomic writer removes its temporary file and the error is reported, instead of
    // SIGXFSZ killing the program with the temporary file left behind.
    #[cfg(unix)]
    // SAFETY: setting a signal to be ignored before any thread starts.
    unsafe {
        libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
    }
    // No transparent huge pages for this process: where the kernel grants them on
    // request (`madvise`, mimalloc asks), a fault on fragmented memory compacts it
    // first. Right after another large process the disk conformal map of the hand took
    // 2.14-2.19 s with them and 1.49-1.54 s without; alone, the same either way.
    #[cfg(target_os = "linux")]
    // SAFETY: a process-wide flag, set before any thread starts; failure is harmless.
    unsafe {
        libc::prctl(libc::PR_SET_THP_DISABLE, 1, 0, 0, 0);
    }
    #[cfg(unix)]
    end_on_sigterm();
    let args = cli::Cli::parse();
    match cli::run(args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", beltrami::report::error_message(e.as_ref()));
            ExitCode::FAILURE
        }
    }
}

/// Ends the program on `SIGTERM` (what a batch job gets when its batch dies, and what
/// `kill` sends) without leaving the temporary files of writes in progress: the signal
/// is blocked in every thread and taken by one that removes them
/// (`beltrami_mesh::io::remove_in_flight`) and exits with 128 + 15, the status of a
/// process the signal ended. Child processes start with the signal unblocked (the
/// standard library resets their signal mask).
#[cfg(unix)]
fn end_on_sigterm() {
    // SAFETY: `set` is initialized by sigemptyset before use; the mask is changed before
    // any other thread starts, so every later thread inherits it.
    let set = unsafe {
        let mut set: libc::sigset_t = std::mem::zeroed();
        libc::sigemptyset(&mut set);
        libc::sigaddset(&mut set, libc::SIGTERM);
        if libc::pthread_sigmask(libc::SIG_BLOCK, &set, std::ptr::null_mut()) != 0 {
            return;
        }
        set
    };
    std::thread::spawn(move || {
        let mut signal = 0;
        // SAFETY: sigwait reads the initialized set and writes the signal number.
        if unsafe { libc::sigwait(&set, &mut signal) } == 0 {
            beltrami_mesh::io::remove_in_flight();
            // SAFETY: ends the process at once; nothing is left to flush that matters
            // for a process being terminated.
            unsafe { libc::_exit(128 + libc::SIGTERM) };
        }
    });
}
