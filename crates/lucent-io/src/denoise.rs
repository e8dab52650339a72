//! `--denoise`: Intel Open Image Denoise (OIDN), loaded at run time, so that lucent
//! builds and runs without it. Its "RT" filter (the one for path-traced images) cleans
//! the linear, HDR colour of a render with the albedo and normal passes as guides.
//!
//! Where the library is looked for, in order (the first that loads wins):
//! 1. `OIDN_LIB`: the library file itself, or a folder holding it;
//! 2. the folder `scripts/install_oidn.sh` installs into:
//!    `$XDG_DATA_HOME/lucent/oidn` (else `~/.local/share/lucent/oidn`);
//! 3. the `pyoidn` wheel of PyPI, which ships the library, in the Python environments
//!    of the usual places (`$VIRTUAL_ENV`, `~/.local`, `/usr/local`, `/usr`, `/opt/conda`);
//! 4. the system's own search (`LD_LIBRARY_PATH`, the linker cache).
//!
//! Only the CPU device is used. OIDN's output depends on its thread count (it splits the
//! image into tiles), so it is given lucent's (`--threads`).

use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::path::{Path, PathBuf};

/// The library's file name (its ABI version 2).
const LIBRARY: &str = "libOpenImageDenoise.so.2";

type Handle = *mut c_void;

/// The entry points lucent calls (OIDN 2's C API, `oidn.h`).
struct Api {
    new_device: unsafe extern "C" fn(c_int) -> Handle,
    set_device_int: unsafe extern "C" fn(Handle, *const c_char, c_int),
    set_device_bool: unsafe extern "C" fn(Handle, *const c_char, bool),
    get_device_int: unsafe extern "C" fn(Handle, *const c_char) -> c_int,
    commit_device: unsafe extern "C" fn(Handle),
    release_device: unsafe extern "C" fn(Handle),
    device_error: unsafe extern "C" fn(Handle, *mut *const c_char) -> c_int,
    new_filter: unsafe extern "C" fn(Handle, *const c_char) -> Handle,
    set_shared_image:
        unsafe extern "C" fn(Handle, *const c_char, *mut c_void, c_int, usize, usize, usize, usize, usize),
    set_filter_bool: unsafe extern "C" fn(Handle, *const c_char, bool),
    commit_filter: unsafe extern "C" fn(Handle),
    execute_filter: unsafe extern "C" fn(Handle),
    release_filter: unsafe extern "C" fn(Handle),
}

/// `OIDN_DEVICE_TYPE_CPU`.
const DEVICE_CPU: c_int = 1;
/// `OIDN_FORMAT_FLOAT3`.
const FORMAT_FLOAT3: c_int = 3;

/// A loaded Open Image Denoise.
pub struct Denoiser {
    api: Api,
    /// Where it was loaded from (for messages and `--stats`).
    pub path: PathBuf,
}

/// The images a denoiser works on: interleaved linear RGB, top row first, all of
/// `width × height` pixels.
pub struct DenoiseInput<'a> {
    pub width: u32,
    pub height: u32,
    pub color: &'a [f32],
    pub albedo: &'a [f32],
    pub normal: &'a [f32],
}

impl Denoiser {
    /// Finds and loads the library; the error says where it looked and how to install it.
    pub fn load() -> Result<Denoiser, String> {
        let mut tried = Vec::new();
        for candidate in candidates() {
            match open(&candidate) {
                Ok(d) => return Ok(d),
                Err(e) => tried.push(e),
            }
        }
        Err(format!(
            "--denoise needs Intel Open Image Denoise, and it was not found ({}). Install it with scripts/install_oidn.sh (it pip-installs the pyoidn wheel, which ships the library, into ~/.local/share/lucent/oidn), or `pip install pyoidn`, or set OIDN_LIB to the path of {LIBRARY}",
            tried.join("; ")
        ))
    }

    /// OIDN's version as `major.minor.patch`.
    pub fn version(&self) -> String {
        let v = self.with_device(1, |device| {
            Ok(unsafe { (self.api.get_device_int)(device, c"version".as_ptr()) })
        });
        match v {
            Ok(v) => format!("{}.{}.{}", v / 10000, v / 100 % 100, v % 100),
            Err(_) => "unknown".into(),
        }
    }

    /// The denoised colour of `input`, on `threads` threads.
    pub fn denoise(&self, input: &DenoiseInput, threads: usize) -> Result<Vec<f32>, String> {
        let n = input.width as usize * input.height as usize * 3;
        for (name, plane) in [
            ("colour", input.color),
            ("albedo", input.albedo),
            ("normal", input.normal),
        ] {
            assert_eq!(plane.len(), n, "denoise: the {name} image has another size");
        }
        let mut output = vec![0f32; n];
        self.with_device(threads, |device| unsafe {
            let api = &self.api;
            let filter = (api.new_filter)(device, c"RT".as_ptr());
            if filter.is_null() {
                return Err("OIDN has no RT filter".to_string());
            }
            let (w, h) = (input.width as usize, input.height as usize);
            let image = |name: &CStr, data: *mut c_void| {
                (api.set_shared_image)(filter, name.as_ptr(), data, FORMAT_FLOAT3, w, h, 0, 12, 12 * w)
            };
            // OIDN reads the inputs only; its API takes mutable pointers.
            image(c"color", input.color.as_ptr() as *mut c_void);
            image(c"albedo", input.albedo.as_ptr() as *mut c_void);
            image(c"normal", input.normal.as_ptr() as *mut c_void);
            image(c"output", output.as_mut_ptr() as *mut c_void);
            (api.set_filter_bool)(filter, c"hdr".as_ptr(), true);
            (api.commit_filter)(filter);
            let result = error(api, device).and_then(|()| {
                (api.execute_filter)(filter);
                error(api, device)
            });
            (api.release_filter)(filter);
            result
        })?;
        Ok(output)
    }

    /// Runs `f` with a committed CPU device of `threads` threads, then releases it.
    fn with_device<T>(&self, threads: usize, f: impl FnOnce(Handle) -> Result<T, String>) -> Result<T, String> {
        let api = &self.api;
        unsafe {
            let device = (api.new_device)(DEVICE_CPU);
            if device.is_null() {
                return Err("OIDN could not create a CPU device".into());
            }
            (api.set_device_int)(device, c"numThreads".as_ptr(), threads.clamp(1, 4096) as c_int);
            // lucent's threads are not pinned to cores; OIDN's should not be either.
            (api.set_device_bool)(device, c"setAffinity".as_ptr(), false);
            (api.commit_device)(device);
            let result = error(api, device).and_then(|()| f(device));
            (api.release_device)(device);
            result
        }
    }
}

/// The device's pending error, if any, as a message.
unsafe fn error(api: &Api, device: Handle) -> Result<(), String> {
    let mut message: *const c_char = std::ptr::null();
    let code = (api.device_error)(device, &mut message);
    if code == 0 {
        return Ok(());
    }
    let text = if message.is_null() {
        String::new()
    } else {
        CStr::from_ptr(message).to_string_lossy().into_owned()
    };
    Err(format!("Open Image Denoise failed (error {code}): {text}"))
}

/// Where the library may be, in the order they are tried.
fn candidates() -> Vec<PathBuf> {
    let mut out = Vec::new();
    if let Some(p) = std::env::var_os("OIDN_LIB") {
        let p = PathBuf::from(p);
        if p.is_dir() {
            out.push(p.join(LIBRARY));
            out.push(p.join("lib").join(LIBRARY));
        } else {
            out.push(p);
        }
        // OIDN_LIB names the library: nothing else is tried.
        return out;
    }
    let home = std::env::var_os("HOME").map(PathBuf::from);
    let data = std::env::var_os("XDG_DATA_HOME")
        .map(PathBuf::from)
        .or_else(|| home.as_ref().map(|h| h.join(".local/share")));
    if let Some(d) = data {
        out.push(d.join("lucent/oidn/pyoidn/oidn/lib").join(LIBRARY));
    }
    let mut prefixes: Vec<PathBuf> = Vec::new();
    if let Some(v) = std::env::var_os("VIRTUAL_ENV") {
        prefixes.push(PathBuf::from(v).join("lib"));
    }
    if let Some(h) = &home {
        prefixes.push(h.join(".local/lib"));
    }
    prefixes.extend(["/usr/local/lib", "/usr/lib", "/opt/conda/lib"].map(PathBuf::from));
    for prefix in prefixes {
        let Ok(entries) = std::fs::read_dir(&prefix) else {
            continue;
        };
        let mut pythons: Vec<PathBuf> = entries
            .flatten()
            .filter(|e| e.file_name().to_string_lossy().starts_with("python3"))
            .map(|e| e.path())
            .collect();
        pythons.sort();
        for python in pythons.iter().rev() {
            for packages in ["site-packages", "dist-packages"] {
                let lib = python.join(packages).join("pyoidn/oidn/lib").join(LIBRARY);
                if lib.exists() {
                    out.push(lib);
                }
            }
        }
    }
    // The system's search: a bare name.
    out.push(PathBuf::from(LIBRARY));
    out
}

/// Loads the library at `path` (a bare name: the system's search) and its entry points.
fn open(path: &Path) -> Result<Denoiser, String> {
    let name =
        CString::new(path.as_os_str().as_encoded_bytes()).map_err(|_| format!("{}: not a path", path.display()))?;
    // SAFETY: dlopen runs the library's initialisers; OIDN's are those of a C++ library
    // built to be loaded this way (its Python wheel does the same).
    let lib = unsafe { libc::dlopen(name.as_ptr(), libc::RTLD_NOW | libc::RTLD_LOCAL) };
    if lib.is_null() {
        let why = unsafe {
            let e = libc::dlerror();
            if e.is_null() {
                "cannot be loaded".to_string()
            } else {
                CStr::from_ptr(e).to_string_lossy().into_owned()
            }
        };
        return Err(if path.is_absolute() && !path.exists() {
            format!("no {}", path.display())
        } else {
            why
        });
    }
    let symbol = |s: &CStr| -> Result<*mut c_void, String> {
        let f = unsafe { libc::dlsym(lib, s.as_ptr()) };
        if f.is_null() {
            Err(format!("{} has no {}", path.display(), s.to_string_lossy()))
        } else {
            Ok(f)
        }
    };
    // SAFETY: each symbol is the C function of oidn.h with the signature given in `Api`.
    unsafe {
        let api = Api {
            new_device: std::mem::transmute::<*mut c_void, _>(symbol(c"oidnNewDevice")?),
            set_device_int: std::mem::transmute::<*mut c_void, _>(symbol(c"oidnSetDeviceInt")?),
            set_device_bool: std::mem::transmute::<*mut c_void, _>(symbol(c"oidnSetDeviceBool")?),
            get_device_int: std::mem::transmute::<*mut c_void, _>(symbol(c"oidnGetDeviceInt")?),
            commit_device: std::mem::transmute::<*mut c_void, _>(symbol(c"oidnCommitDevice")?),
            release_device: std::mem::transmute::<*mut c_void, _>(symbol(c"oidnReleaseDevice")?),
            device_error: std::mem::transmute::<*mut c_void, _>(symbol(c"oidnGetDeviceError")?),
            new_filter: std::mem::transmute::<*mut c_void, _>(symbol(c"oidnNewFilter")?),
            set_shared_image: std::mem::transmute::<*mut c_void, _>(symbol(c"oidnSetSharedFilterImage")?),
            set_filter_bool: std::mem::transmute::<*mut c_void, _>(symbol(c"oidnSetFilterBool")?),
            commit_filter: std::mem::transmute::<*mut c_void, _>(symbol(c"oidnCommitFilter")?),
            execute_filter: std::mem::transmute::<*mut c_void, _>(symbol(c"oidnExecuteFilter")?),
            release_filter: std::mem::transmute::<*mut c_void, _>(symbol(c"oidnReleaseFilter")?),
        };
        Ok(Denoiser {
            api,
            path: path.to_path_buf(),
        })
    }
}
