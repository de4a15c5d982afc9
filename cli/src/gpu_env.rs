//! Quiets Mesa's Vulkan device-selection layer where its Wayland probe can only fail loudly.
//!
//! # Why
//! Mesa installs `VK_LAYER_MESA_device_select` as an implicit layer: it reorders the physical
//! devices so that the one driving the display comes first. wgpu enables every window-system
//! extension the loader offers, `VK_KHR_wayland_surface` included, and with that extension enabled
//! the layer calls `wl_display_connect(NULL)` each time devices are enumerated (twice per start).
//! Without `XDG_RUNTIME_DIR` (Xvfb, containers, `ssh` sessions without logind) libwayland cannot
//! find a socket and prints `error: XDG_RUNTIME_DIR is invalid or not set in the environment.` on
//! stderr each time, although nothing went wrong.
//!
//! # What
//! [`quiet_device_select`] sets `NODEVICE_SELECT=1` (the layer's own off switch, honoured by the
//! Vulkan loader) in exactly that case: no `WAYLAND_SOCKET`, no absolute `WAYLAND_DISPLAY` and no
//! usable `XDG_RUNTIME_DIR`, so the layer's Wayland probe cannot succeed anyway. It is left alone
//! when the user asks the layer for a device (`MESA_VK_DEVICE_SELECT`, `DRI_PRIME`) or sets
//! `NODEVICE_SELECT` either way. On a normal desktop `XDG_RUNTIME_DIR` is set, so nothing changes
//! there. What is lost where it applies: on a machine with several GPUs and an X display but no
//! `XDG_RUNTIME_DIR`, the layer's preference for the X screen's GPU; wgpu's own choice (and the
//! window's surface compatibility check) then decides.
//!
//! The variable must be set before any thread exists (setting the environment is not thread
//! safe), so `main` calls this first; this module is the crate's second `unsafe` place.
#![allow(unsafe_code)]

/// The layer's off switch.
const DISABLE: &str = "NODEVICE_SELECT";

/// Whether the device-select layer should be disabled, given how the environment reads
/// (`get(name)` is the variable's value, `None` when unset).
pub fn should_disable(get: impl Fn(&str) -> Option<std::ffi::OsString>) -> bool {
    let set = |name: &str| get(name).is_some_and(|v| !v.is_empty());
    if set(DISABLE) || set("MESA_VK_DEVICE_SELECT") || set("DRI_PRIME") || set("WAYLAND_SOCKET") {
        return false;
    }
    let absolute = |name: &str| get(name).is_some_and(|v| v.as_encoded_bytes().first() == Some(&b'/'));
    // libwayland resolves a relative display name (or the default "wayland-0") inside
    // XDG_RUNTIME_DIR, and complains when that is unset or not an absolute path.
    !absolute("WAYLAND_DISPLAY") && !absolute("XDG_RUNTIME_DIR")
}

/// Sets `NODEVICE_SELECT=1` when [`should_disable`] says so. Call before any thread is spawned.
pub fn quiet_device_select() {
    if should_disable(|name| std::env::var_os(name)) {
        // SAFETY: called first thing in `main`, before the program has spawned any thread, so no
        // other thread can be reading or writing the environment.
        unsafe { std::env::set_var(DISABLE, "1") };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::ffi::OsString;

    fn env<'a>(vars: &'a [(&'a str, &'a str)]) -> impl Fn(&str) -> Option<OsString> + 'a {
        move |name| vars.iter().find(|(k, _)| *k == name).map(|(_, v)| OsString::from(v))
    }

    #[test]
    fn disables_only_where_the_wayland_probe_must_fail() {
        // Xvfb or a container: no runtime dir, no Wayland.
        assert!(should_disable(env(&[("DISPLAY", ":99")])));
        assert!(should_disable(env(&[("XDG_RUNTIME_DIR", "relative/dir"), ("WAYLAND_DISPLAY", "wayland-0")])));
        // A normal desktop, X11 or Wayland.
        assert!(!should_disable(env(&[("DISPLAY", ":0"), ("XDG_RUNTIME_DIR", "/run/user/1000")])));
        assert!(!should_disable(env(&[("WAYLAND_DISPLAY", "wayland-0"), ("XDG_RUNTIME_DIR", "/run/user/1000")])));
        // A Wayland socket reachable without the runtime dir.
        assert!(!should_disable(env(&[("WAYLAND_DISPLAY", "/tmp/wayland-1")])));
        assert!(!should_disable(env(&[("WAYLAND_SOCKET", "5")])));
        // The user's own choices win.
        assert!(!should_disable(env(&[("NODEVICE_SELECT", "0")])));
        assert!(!should_disable(env(&[("MESA_VK_DEVICE_SELECT", "10005:0")])));
        assert!(!should_disable(env(&[("DRI_PRIME", "1")])));
    }
}
