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
    match stat_fields(pid) {
        Some(fields) => !matches!(fields.first().map(String::as_str), Some("Z" | "X")),
        None => false,
    }
}

/// When process `pid` started, in clock ticks since boot (`/proc`'s
/// `starttime`): with its pid, what names one process, since a pid is
/// reused once its process ends. `None` where it is not running or there
/// is no `/proc`.
pub fn process_start(pid: u32) -> Option<u64> {
    stat_fields(pid)?.get(19)?.parse().ok()
}

/// The fields of `/proc/PID/stat` after the command, from the state on.
fn stat_fields(pid: u32) -> Option<Vec<String>> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    // `PID (COMMAND) STATE ...`; the command may hold spaces and ')'.
    let (_, rest) = stat.rsplit_once(')')?;
    Some(rest.split_whitespace().map(str::to_owned).collect())
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
            assert_eq!(process_start(pid), None);
            let mine = process_start(std::process::id()).unwrap();
            assert_eq!(process_start(std::process::id()), Some(mine));
            assert_ne!(process_start(1), Some(mine));
        }
    }
}
