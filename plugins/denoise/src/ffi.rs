//! A minimal binding of Open Image Denoise 2's C API (`OpenImageDenoise/oidn.h`):
//! a CPU device, `RT` filters over shared images, and errors read back with
//! `oidnGetDeviceError` after every call that can fail. The only unsafe code
//! of the crate.
#![allow(unsafe_code)]

use std::ffi::{c_char, c_int, c_void, CStr};
use std::ptr::NonNull;

use lumis_api::{Error, Result};

#[repr(C)]
struct DeviceImpl {
    _opaque: [u8; 0],
}

#[repr(C)]
struct FilterImpl {
    _opaque: [u8; 0],
}

/// `OIDN_DEVICE_TYPE_CPU`: the wheel route ships only the CPU module, and a
/// CPU device gives the same result on every machine.
const DEVICE_TYPE_CPU: c_int = 1;
/// `OIDN_FORMAT_FLOAT3`.
const FORMAT_FLOAT3: c_int = 3;
/// `OIDN_ERROR_NONE`.
const ERROR_NONE: c_int = 0;

#[link(name = "OpenImageDenoise")]
extern "C" {
    fn oidnNewDevice(device_type: c_int) -> *mut DeviceImpl;
    fn oidnCommitDevice(device: *mut DeviceImpl);
    fn oidnReleaseDevice(device: *mut DeviceImpl);
    fn oidnGetDeviceInt(device: *mut DeviceImpl, name: *const c_char) -> c_int;
    fn oidnGetDeviceError(device: *mut DeviceImpl, message: *mut *const c_char) -> c_int;
    fn oidnNewFilter(device: *mut DeviceImpl, filter_type: *const c_char) -> *mut FilterImpl;
    fn oidnSetSharedFilterImage(
        filter: *mut FilterImpl,
        name: *const c_char,
        pointer: *mut c_void,
        format: c_int,
        width: usize,
        height: usize,
        byte_offset: usize,
        pixel_byte_stride: usize,
        row_byte_stride: usize,
    );
    fn oidnSetFilterBool(filter: *mut FilterImpl, name: *const c_char, value: bool);
    fn oidnSetFilterInt(filter: *mut FilterImpl, name: *const c_char, value: c_int);
    fn oidnCommitFilter(filter: *mut FilterImpl);
    fn oidnExecuteFilter(filter: *mut FilterImpl);
    fn oidnReleaseFilter(filter: *mut FilterImpl);
}

/// An OIDN CPU device, released when dropped.
pub struct Device(NonNull<DeviceImpl>);

impl Device {
    pub fn cpu() -> Result<Self> {
        // SAFETY: no precondition; a null handle is turned into an error.
        let raw = unsafe { oidnNewDevice(DEVICE_TYPE_CPU) };
        let device = NonNull::new(raw).map(Self).ok_or_else(|| {
            Error::msg("Open Image Denoise: no CPU device could be created (unsupported CPU?)")
        })?;
        // SAFETY: a live device handle.
        unsafe { oidnCommitDevice(device.0.as_ptr()) };
        device.check("creating the CPU device")?;
        Ok(device)
    }

    /// The library version as `major * 10000 + minor * 100 + patch`.
    pub fn version(&self) -> Result<u32> {
        // SAFETY: a live device handle and a NUL-terminated name.
        let version = unsafe { oidnGetDeviceInt(self.0.as_ptr(), c"version".as_ptr()) };
        self.check("reading the version")?;
        u32::try_from(version)
            .map_err(|_| Error::msg(format!("Open Image Denoise reports version {version}")))
    }

    /// The first error since the last check, as an error naming `doing`.
    fn check(&self, doing: &str) -> Result<()> {
        let mut message: *const c_char = std::ptr::null();
        // SAFETY: a live device handle; OIDN sets `message` to a string it
        // owns until the next call on the device, which is copied at once.
        let code = unsafe { oidnGetDeviceError(self.0.as_ptr(), &mut message) };
        if code == ERROR_NONE {
            return Ok(());
        }
        let text = if message.is_null() {
            "no message".to_string()
        } else {
            // SAFETY: non-null, NUL-terminated, alive until the next call.
            unsafe { CStr::from_ptr(message) }
                .to_string_lossy()
                .into_owned()
        };
        Err(Error::msg(format!(
            "Open Image Denoise failed {doing} (error {code}): {text}"
        )))
    }
}

impl Drop for Device {
    fn drop(&mut self) {
        // SAFETY: the handle is live and released once.
        unsafe { oidnReleaseDevice(self.0.as_ptr()) }
    }
}

/// An `RT` filter's images: each `width * height` RGB pixels. The shared
/// images are read (and `output` written) only inside [`run_rt_filter`],
/// while these borrows are held.
pub struct RtImages<'a> {
    pub width: usize,
    pub height: usize,
    pub color: &'a mut [[f32; 3]],
    pub albedo: Option<&'a mut [[f32; 3]]>,
    pub normal: Option<&'a mut [[f32; 3]]>,
    pub output: &'a mut [[f32; 3]],
}

/// An `RT` filter's settings (`quality` is an `OIDNQuality` value).
pub struct RtSettings {
    pub quality: i32,
    pub hdr: bool,
    pub clean_aux: bool,
}

/// Runs one `RT` (ray-tracing) filter on `device`.
pub fn run_rt_filter(device: &Device, images: RtImages<'_>, settings: &RtSettings) -> Result<()> {
    let pixels = images.width * images.height;
    let all = [
        Some(&*images.color),
        images.albedo.as_deref(),
        images.normal.as_deref(),
        Some(&*images.output),
    ];
    if all.iter().flatten().any(|image| image.len() != pixels) {
        return Err(Error::msg(format!(
            "Open Image Denoise: every image must hold {}x{} pixels",
            images.width, images.height
        )));
    }
    // SAFETY: a live device handle; a null filter is turned into an error.
    let raw = unsafe { oidnNewFilter(device.0.as_ptr(), c"RT".as_ptr()) };
    let filter = NonNull::new(raw).map(Filter).ok_or_else(|| {
        device
            .check("creating the RT filter")
            .err()
            .unwrap_or_else(|| Error::msg("Open Image Denoise: no RT filter"))
    })?;
    let shared = [
        (c"color", Some(images.color)),
        (c"albedo", images.albedo),
        (c"normal", images.normal),
        (c"output", Some(images.output)),
    ];
    for (name, image) in shared {
        let Some(image) = image else { continue };
        // SAFETY: `image` is `width * height` tightly packed float RGB
        // pixels (checked above), borrowed for the whole filter run; the
        // filter is released before this function returns.
        unsafe {
            oidnSetSharedFilterImage(
                filter.0.as_ptr(),
                name.as_ptr(),
                image.as_mut_ptr().cast(),
                FORMAT_FLOAT3,
                images.width,
                images.height,
                0,
                0,
                0,
            )
        };
    }
    // SAFETY: a live filter handle and NUL-terminated names.
    unsafe {
        oidnSetFilterBool(filter.0.as_ptr(), c"hdr".as_ptr(), settings.hdr);
        oidnSetFilterBool(filter.0.as_ptr(), c"cleanAux".as_ptr(), settings.clean_aux);
        oidnSetFilterInt(filter.0.as_ptr(), c"quality".as_ptr(), settings.quality);
        oidnCommitFilter(filter.0.as_ptr());
    }
    device.check("setting up the RT filter")?;
    // SAFETY: a committed filter whose images are borrowed (see above).
    unsafe { oidnExecuteFilter(filter.0.as_ptr()) };
    device.check("running the RT filter")
}

/// An OIDN filter, released when dropped.
struct Filter(NonNull<FilterImpl>);

impl Drop for Filter {
    fn drop(&mut self) {
        // SAFETY: the handle is live and released once.
        unsafe { oidnReleaseFilter(self.0.as_ptr()) }
    }
}
