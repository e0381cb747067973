//! Whether a process that left a file behind (a lock, a temporary file)
//! still runs.

/// Whether process `pid` is running on this machine. Read from `/proc`;
/// where there is no `/proc` every process counts as running, so nothing
/// another process may still use is ever taken or deleted.
pub fn process_is_running(pid: u32) -> bool {
    if pid == std::process::id() {
        return true;
    }
    let proc_root = std::path::Path::new("/proc");
    !proc_root.join("self").exists() || proc_root.join(pid.to_string()).exists()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn this_process_runs_and_a_reaped_child_does_not() {
        assert!(process_is_running(std::process::id()));
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let pid = child.id();
        child.wait().unwrap();
        if std::path::Path::new("/proc/self").exists() {
            assert!(!process_is_running(pid));
        }
    }
}
