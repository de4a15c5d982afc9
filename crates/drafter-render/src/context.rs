//! The wgpu instance, adapter, device and queue.
//!
//! Headless rendering needs no window: on a machine without a GPU, Mesa's lavapipe (`apt-get
//! install mesa-vulkan-drivers libvulkan1`) provides a Vulkan CPU device that wgpu picks up with no
//! configuration. `WGPU_BACKEND` (e.g. `vulkan`, `gl`) and `WGPU_ADAPTER_NAME` choose explicitly.

/// Why rendering could not start or finish.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// No adapter: no GPU and no software Vulkan/GL driver.
    #[error(
        "no GPU adapter found ({0}); headless rendering needs a Vulkan or GL driver: on Debian/Ubuntu \
         `apt-get install mesa-vulkan-drivers libvulkan1` (lavapipe, a CPU Vulkan device)"
    )]
    NoAdapter(String),
    /// An adapter was found but lacks a capability the passes need (e.g. Mesa's GLES fallback
    /// cannot render to 32-bit float targets).
    #[error(
        "the GPU adapter {0} cannot be used: {1}; install a Vulkan driver (on Debian/Ubuntu \
         `apt-get install mesa-vulkan-drivers libvulkan1`) or choose another adapter with \
         WGPU_BACKEND / WGPU_ADAPTER_NAME"
    )]
    Unsupported(String, String),
    #[error("the GPU adapter refused a device: {0}")]
    Device(String),
    /// Options outside their documented ranges (the caller's fault).
    #[error("invalid render options: {0}")]
    Options(String),
    /// A GPU operation failed (validation, out of memory, lost device).
    #[error("GPU error: {0}")]
    Gpu(String),
    /// No model has been given to the renderer yet.
    #[error("no model loaded")]
    NoModel,
}

/// The device every pass is created on.
#[derive(Debug)]
pub struct Gpu {
    pub instance: wgpu::Instance,
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
}

impl Gpu {
    /// A device for offscreen rendering (environment variables respected, see the module docs).
    ///
    /// Mesa 22's lavapipe crashes in `vkCmdBeginDebugUtilsLabelEXT`, which wgpu calls for debug
    /// groups when the instance has [`wgpu::InstanceFlags::DEBUG`] (the default of debug builds). On
    /// lavapipe the instance is therefore made again without that flag, unless `WGPU_DEBUG` asks
    /// for it explicitly; debug groups are then no-ops.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn headless() -> Result<Gpu, RenderError> {
        let descriptor = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        let debug = descriptor.flags.contains(wgpu::InstanceFlags::DEBUG);
        let (instance, adapter) = Self::adapter(descriptor)?;
        let info = adapter.get_info();
        if debug && info.driver == "llvmpipe" && std::env::var_os("WGPU_DEBUG").is_none() {
            drop((adapter, instance));
            let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
            descriptor.flags.remove(wgpu::InstanceFlags::DEBUG);
            let (instance, adapter) = Self::adapter(descriptor)?;
            return Self::with_adapter(instance, adapter);
        }
        Self::with_adapter(instance, adapter)
    }

    #[cfg(not(target_arch = "wasm32"))]
    fn adapter(descriptor: wgpu::InstanceDescriptor) -> Result<(wgpu::Instance, wgpu::Adapter), RenderError> {
        let instance = wgpu::Instance::new(descriptor);
        let adapter = pollster::block_on(wgpu::util::initialize_adapter_from_env_or_default(&instance, None))
            .map_err(|e| RenderError::NoAdapter(e.to_string()))?;
        Ok((instance, adapter))
    }

    /// A device on `adapter` (the window chooses one compatible with its surface).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn with_adapter(instance: wgpu::Instance, adapter: wgpu::Adapter) -> Result<Gpu, RenderError> {
        pollster::block_on(Self::request(instance, adapter))
    }

    /// A device on `adapter`, without blocking: the browser's way (`web/`), where the device
    /// arrives through a promise. [`Self::with_adapter`] waits for the same request.
    pub async fn request(instance: wgpu::Instance, adapter: wgpu::Adapter) -> Result<Gpu, RenderError> {
        Self::check_capabilities(&adapter)?;
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("drafter device"),
                required_features: wgpu::Features::empty(),
                required_limits: adapter.limits(),
                ..Default::default()
            })
            .await
            .map_err(|e| RenderError::Device(e.to_string()))?;
        Ok(Gpu { instance, adapter, device, queue })
    }

    /// Fails with a clear message, before any pipeline is made, when the adapter cannot render to
    /// a target format the passes use (wgpu would otherwise report a validation error on the
    /// first pipeline). GLES without `EXT_color_buffer_float` is the case seen in practice: wgpu
    /// falls back to it when no Vulkan driver is installed.
    fn check_capabilities(adapter: &wgpu::Adapter) -> Result<(), RenderError> {
        let renderable = |format: wgpu::TextureFormat| {
            adapter.get_texture_format_features(format).allowed_usages.contains(wgpu::TextureUsages::RENDER_ATTACHMENT)
        };
        use crate::targets::*;
        let targets = [
            COLOR_FORMAT,
            NORMAL_FORMAT,
            LINEAR_DEPTH_FORMAT,
            PART_ID_FORMAT,
            DEPTH_FORMAT,
            BLUR_FORMAT,
            SHADOW_MASK_FORMAT,
            SHADOW_STENCIL_FORMAT,
        ];
        for format in targets {
            if !renderable(format) {
                let info = adapter.get_info();
                return Err(RenderError::Unsupported(
                    format!("'{}' ({:?})", info.name, info.backend),
                    format!("it cannot render to {format:?} targets"),
                ));
            }
        }
        Ok(())
    }

    /// "name (backend, device type)", e.g. "llvmpipe (LLVM 15.0.6, 256 bits) (Vulkan, Cpu)".
    /// The resolution divisor of interactive frames on this adapter
    /// ([`crate::RenderOptions::interactive_scale`]): larger on a CPU rasteriser.
    pub fn interactive_scale(&self) -> u32 {
        if self.adapter.get_info().device_type == wgpu::DeviceType::Cpu {
            crate::style::CPU_INTERACTIVE_SCALE
        } else {
            crate::style::INTERACTIVE_SCALE
        }
    }

    pub fn description(&self) -> String {
        let info = self.adapter.get_info();
        format!("{} ({:?}, {:?})", info.name, info.backend, info.device_type)
    }
}
