//! The Embree device and its error reporting.

use std::ffi::{c_char, c_void, CStr};
use std::sync::atomic::{AtomicI64, Ordering};
use std::sync::{Arc, Mutex};

use embree4_sys as sys;

/// An error reported by Embree through the device error callback.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("Embree error {code}: {message}")]
pub struct EmbreeError {
    pub code: String,
    pub message: String,
}

/// Errors raised by Embree since the last check, filled by [`error_callback`].
type ErrorSlot = Mutex<Option<EmbreeError>>;

struct DeviceInner {
    raw: sys::RTCDevice,
    /// Boxed so its address stays fixed: Embree holds it as the callback's
    /// user pointer for the device's lifetime.
    errors: Box<ErrorSlot>,
    /// Bytes Embree holds (BVHs, its copies of buffers), kept by
    /// [`memory_callback`]; boxed for the same reason as `errors`.
    memory: Box<AtomicI64>,
}

// SAFETY: an Embree device is thread-safe (Embree 4 API: all device functions
// may be called from any thread); the error slot is behind a Mutex.
unsafe impl Send for DeviceInner {}
// SAFETY: as above.
unsafe impl Sync for DeviceInner {}

impl Drop for DeviceInner {
    fn drop(&mut self) {
        // SAFETY: `raw` came from rtcNewDevice and this is the last owner
        // (scenes hold an `Arc` to the inner device).
        unsafe { sys::rtcReleaseDevice(self.raw) }
    }
}

/// A reference-counted Embree device.
#[derive(Clone)]
pub struct Device {
    inner: Arc<DeviceInner>,
}

impl std::fmt::Debug for Device {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Device").finish_non_exhaustive()
    }
}

unsafe extern "C" fn error_callback(
    user: *mut c_void,
    code: sys::RTCError,
    message: *const c_char,
) {
    // SAFETY: `user` is the address of the boxed ErrorSlot owned by the
    // DeviceInner that registered this callback; Embree only calls it while
    // the device is alive. `message` is a NUL-terminated string or null.
    let slot = unsafe { &*(user as *const ErrorSlot) };
    let message = if message.is_null() {
        String::new()
    } else {
        unsafe { CStr::from_ptr(message) }
            .to_string_lossy()
            .into_owned()
    };
    let error = EmbreeError {
        code: format!("{code:?}"),
        message,
    };
    if let Ok(mut guard) = slot.lock() {
        // Keep the first error: later ones are usually its consequences.
        guard.get_or_insert(error);
    }
}

unsafe extern "C" fn memory_callback(user: *mut c_void, bytes: isize, _post: bool) -> bool {
    // SAFETY: `user` is the address of the boxed AtomicI64 owned by the
    // DeviceInner that registered this callback, alive as long as the device.
    let counter = unsafe { &*(user as *const AtomicI64) };
    // Embree reports allocations as positive and frees as negative sizes;
    // returning true lets every allocation proceed.
    counter.fetch_add(bytes as i64, Ordering::Relaxed);
    true
}

impl Device {
    /// Creates a device with Embree's default configuration.
    pub fn new() -> Result<Self, EmbreeError> {
        Self::with_config("")
    }

    /// Creates a device with an Embree configuration string (e.g. `"threads=1"`).
    pub fn with_config(config: &str) -> Result<Self, EmbreeError> {
        let config = std::ffi::CString::new(config).map_err(|_| EmbreeError {
            code: "INVALID_ARGUMENT".into(),
            message: "device configuration contains a NUL byte".into(),
        })?;
        // SAFETY: `config` is a valid NUL-terminated string for the call.
        let raw = unsafe { sys::rtcNewDevice(config.as_ptr()) };
        if raw.is_null() {
            // SAFETY: rtcGetDeviceError accepts null and reports the error of
            // the failed device creation.
            let code = unsafe { sys::rtcGetDeviceError(std::ptr::null_mut()) };
            return Err(EmbreeError {
                code: format!("{code:?}"),
                message: "rtcNewDevice failed (unsupported CPU or bad configuration?)".into(),
            });
        }
        let errors: Box<ErrorSlot> = Box::new(Mutex::new(None));
        // SAFETY: `raw` is a live device; the user pointer is the boxed slot,
        // which DeviceInner keeps alive (and at a fixed address) until
        // rtcReleaseDevice in Drop.
        unsafe {
            sys::rtcSetDeviceErrorFunction(
                raw,
                Some(error_callback),
                &*errors as *const ErrorSlot as *mut c_void,
            )
        };
        let memory = Box::new(AtomicI64::new(0));
        // SAFETY: as for the error function: the user pointer is the boxed
        // counter, kept alive and in place by DeviceInner until release.
        unsafe {
            sys::rtcSetDeviceMemoryMonitorFunction(
                raw,
                Some(memory_callback),
                &*memory as *const AtomicI64 as *mut c_void,
            )
        };
        Ok(Self {
            inner: Arc::new(DeviceInner {
                raw,
                errors,
                memory,
            }),
        })
    }

    /// Whether both handles name the same Embree device.
    pub fn same_as(&self, other: &Device) -> bool {
        Arc::ptr_eq(&self.inner, &other.inner)
    }

    pub(crate) fn raw(&self) -> sys::RTCDevice {
        self.inner.raw
    }

    /// Returns the first error Embree reported since the last call, if any.
    pub(crate) fn take_error(&self) -> Result<(), EmbreeError> {
        match self.inner.errors.lock() {
            Ok(mut guard) => guard.take().map_or(Ok(()), Err),
            Err(_) => Err(EmbreeError {
                code: "UNKNOWN".into(),
                message: "error slot poisoned".into(),
            }),
        }
    }

    /// Bytes Embree currently holds on this device (its BVHs and internal
    /// data; shared buffers are not counted, they belong to the caller).
    pub fn memory_in_use(&self) -> i64 {
        self.inner.memory.load(Ordering::Relaxed)
    }

    /// Embree's version as `major * 10000 + minor * 100 + patch`.
    pub fn version(&self) -> i64 {
        // SAFETY: `raw` is a live device; querying a property has no side effect.
        unsafe { sys::rtcGetDeviceProperty(self.raw(), sys::RTCDeviceProperty::VERSION) as i64 }
    }
}
