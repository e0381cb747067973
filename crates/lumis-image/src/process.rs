//! Whether a process that left a file behind (a lock, a temporary file)
//! still runs.

/// Whether process `pid` is running on this machine. Read from `/proc`; a
/// zombie (killed, not yet reaped by its parent) has stopped. Where there
/// is no `/proc` every process counts as running, so nothing another
/// process may still use is ever taken or deleted.
pub fn process_is_running(pid: u32) -> bool {
    if pid == std::process::id() {
        return true;
    }
    let proc_root = std::path::Path::new("/proc");
    if !proc_root.join("self").exists() {
        return true;
    }
    match std::fs::read_to_string(proc_root.join(pid.to_string()).join("stat")) {
        // `PID (COMMAND) STATE ...`; the command may hold spaces and ')'.
        Ok(stat) => !matches!(
            stat.rsplit_once(')')
                .map(|(_, rest)| rest.trim_start().chars().next()),
            Some(Some('Z' | 'X'))
        ),
        Err(_) => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn this_process_runs_and_a_reaped_child_does_not() {
        assert!(process_is_running(std::process::id()));
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let pid = child.id();
        if std::path::Path::new("/proc/self").exists() {
            // Ended but not yet reaped: a zombie, not running.
            while std::fs::read_to_string(format!("/proc/{pid}/stat"))
                .is_ok_and(|s| !s.contains(") Z"))
            {
                std::thread::yield_now();
            }
            assert!(!process_is_running(pid));
        }
        child.wait().unwrap();
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let pid = child.id();
        child.wait().unwrap();
        if std::path::Path::new("/proc/self").exists() {
            assert!(!process_is_running(pid));
        }
    }
}
