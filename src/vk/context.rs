//! Instance, device choice, queue, memory allocator and the validation messenger.

use std::ffi::{c_void, CStr, CString};
use std::mem::ManuallyDrop;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Arc, Mutex};

use anyhow::{anyhow, bail, Context as _, Result};
use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};

/// How to create a [`Context`].
#[derive(Clone, Debug, Default)]
pub struct ContextOptions {
    /// Enable the Khronos validation layer with synchronization validation.
    pub validation: bool,
    /// Pick the first device whose name contains this (case-insensitive).
    pub device: Option<String>,
    /// Instance extensions a window surface needs.
    pub surface_extensions: Vec<&'static CStr>,
}

/// Optional device features voxcone uses when present.
#[derive(Clone, Copy, Debug, Default)]
pub struct Features {
    pub geometry_shader: bool,
    pub fragment_stores_and_atomics: bool,
    pub sampler_anisotropy: bool,
    pub depth_clamp: bool,
}

/// The Vulkan device and everything created once with it. Resources hold an `Arc` of it,
/// so it is destroyed last.
pub struct Context {
    pub entry: ash::Entry,
    pub instance: ash::Instance,
    pub physical_device: vk::PhysicalDevice,
    pub device: ash::Device,
    pub queue: vk::Queue,
    pub queue_family: u32,
    pub properties: vk::PhysicalDeviceProperties,
    pub driver: String,
    pub features: Features,
    pub allocator: ManuallyDrop<Mutex<Allocator>>,
    debug_utils: Option<DebugUtils>,
    validation_messages: Box<AtomicU32>,
}

struct DebugUtils {
    instance: ash::ext::debug_utils::Instance,
    device: ash::ext::debug_utils::Device,
    messenger: Option<vk::DebugUtilsMessengerEXT>,
}

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    kind: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    // SAFETY: the layer passes a valid callback-data pointer; `user` is the counter boxed
    // in the `Context` that outlives the messenger.
    let message = unsafe {
        let data = &*data;
        if data.p_message.is_null() {
            String::new()
        } else {
            CStr::from_ptr(data.p_message)
                .to_string_lossy()
                .into_owned()
        }
    };
    if severity.intersects(
        vk::DebugUtilsMessageSeverityFlagsEXT::WARNING
            | vk::DebugUtilsMessageSeverityFlagsEXT::ERROR,
    ) {
        unsafe { &*(user as *const AtomicU32) }.fetch_add(1, Ordering::SeqCst);
        log::error!("[vulkan {kind:?}] {message}");
    } else {
        log::debug!("[vulkan {kind:?}] {message}");
    }
    vk::FALSE
}

fn device_rank(kind: vk::PhysicalDeviceType) -> u32 {
    match kind {
        vk::PhysicalDeviceType::DISCRETE_GPU => 0,
        vk::PhysicalDeviceType::INTEGRATED_GPU => 1,
        vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
        vk::PhysicalDeviceType::CPU => 3,
        _ => 4,
    }
}

const NO_DEVICE_HELP: &str = "install a Vulkan driver: on Debian/Ubuntu `apt-get install \
     mesa-vulkan-drivers libvulkan1` gives the CPU driver lavapipe; `vulkaninfo --summary` \
     (package vulkan-tools) lists what the loader finds";

/// The host's physical memory, bytes, where the system says.
#[cfg(unix)]
fn host_physical_bytes() -> Option<u64> {
    // SAFETY: sysconf reads system constants; it has no preconditions.
    let (pages, page) = unsafe {
        (
            libc::sysconf(libc::_SC_PHYS_PAGES),
            libc::sysconf(libc::_SC_PAGESIZE),
        )
    };
    let pages = u64::try_from(pages).ok()?;
    let page = u64::try_from(page).ok()?;
    pages.checked_mul(page)
}

/// The host's physical memory, bytes, where the system says.
#[cfg(not(unix))]
fn host_physical_bytes() -> Option<u64> {
    None
}

impl Context {
    /// Whether the device is a CPU driver (lavapipe): there each workgroup costs more
    /// than a GPU's idle lanes, and some passes pick other strategies.
    pub fn is_cpu(&self) -> bool {
        self.properties.device_type == vk::PhysicalDeviceType::CPU
    }

    /// The largest device-local memory heap, bytes. A CPU driver's device memory is the
    /// host's, allocated as it is asked for (lavapipe's vkAllocateMemory is a malloc that
    /// checks no heap), so there it is the host's physical memory where that is larger
    /// than the heap the driver reports: Mesa 22.3's lavapipe reports a fixed 2 GiB, later
    /// ones the host's physical memory.
    pub fn device_local_bytes(&self) -> u64 {
        // SAFETY: `physical_device` was enumerated from `instance`, which outlives `self`.
        let memory = unsafe {
            self.instance
                .get_physical_device_memory_properties(self.physical_device)
        };
        let heap = memory.memory_heaps[..memory.memory_heap_count as usize]
            .iter()
            .filter(|heap| heap.flags.contains(vk::MemoryHeapFlags::DEVICE_LOCAL))
            .map(|heap| heap.size)
            .max()
            .unwrap_or(0);
        if self.is_cpu() {
            heap.max(host_physical_bytes().unwrap_or(0))
        } else {
            heap
        }
    }

    pub fn new(options: &ContextOptions) -> Result<Arc<Self>> {
        // SAFETY: loading the system Vulkan loader; failure is reported, not assumed.
        let entry = unsafe { ash::Entry::load() }.map_err(|e| {
            anyhow!("cannot load the Vulkan loader (libvulkan.so.1): {e}; {NO_DEVICE_HELP}")
        })?;

        if options.validation {
            let layers = unsafe { entry.enumerate_instance_layer_properties() }?;
            let found = layers
                .iter()
                .any(|l| l.layer_name_as_c_str().is_ok_and(|n| n == VALIDATION_LAYER));
            if !found {
                bail!(
                    "validation was requested but the layer {} is not installed \
                     (Debian/Ubuntu: apt-get install vulkan-validationlayers)",
                    VALIDATION_LAYER.to_string_lossy()
                );
            }
            // Hazards across submits are checked only when this is in the environment
            // when the layer loads (measured, see shared/notes/lavapipe.md).
            if std::env::var_os("VK_LAYER_ENABLES").is_none() {
                // SAFETY: set before any other thread of ours reads the environment.
                unsafe {
                    std::env::set_var(
                        "VK_LAYER_ENABLES",
                        "VALIDATION_CHECK_ENABLE_SYNCHRONIZATION_VALIDATION_QUEUE_SUBMIT",
                    )
                };
            }
        }

        let app_name = CString::new("voxcone").unwrap();
        let app_info = vk::ApplicationInfo::default()
            .application_name(&app_name)
            .application_version(1)
            .engine_name(&app_name)
            .api_version(vk::API_VERSION_1_3);
        let mut extensions: Vec<*const i8> = options
            .surface_extensions
            .iter()
            .map(|e| e.as_ptr())
            .collect();
        let mut layers = Vec::new();
        // Labels and object names are wanted under profilers too, so debug utils is
        // enabled whenever the loader (or an injected capture layer) offers it.
        let available = unsafe { entry.enumerate_instance_extension_properties(None) }?;
        let has_debug_utils = options.validation
            || available.iter().any(|e| {
                e.extension_name_as_c_str()
                    .is_ok_and(|n| n == ash::ext::debug_utils::NAME)
            });
        if has_debug_utils {
            extensions.push(ash::ext::debug_utils::NAME.as_ptr());
        }
        if options.validation {
            layers.push(VALIDATION_LAYER.as_ptr());
        }
        let validation_messages = Box::new(AtomicU32::new(0));
        let messenger_info = || {
            vk::DebugUtilsMessengerCreateInfoEXT::default()
                .message_severity(
                    vk::DebugUtilsMessageSeverityFlagsEXT::WARNING
                        | vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
                        | vk::DebugUtilsMessageSeverityFlagsEXT::INFO,
                )
                .message_type(
                    vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                        | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                        | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
                )
                .pfn_user_callback(Some(debug_callback))
                .user_data(&*validation_messages as *const AtomicU32 as *mut c_void)
        };
        let enables = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
        let mut validation_features =
            vk::ValidationFeaturesEXT::default().enabled_validation_features(&enables);
        // A messenger chained to the instance reports messages of instance creation itself.
        let mut instance_messenger = messenger_info();
        let mut instance_info = vk::InstanceCreateInfo::default()
            .application_info(&app_info)
            .enabled_extension_names(&extensions)
            .enabled_layer_names(&layers);
        if options.validation {
            instance_info = instance_info
                .push_next(&mut validation_features)
                .push_next(&mut instance_messenger);
        }
        let instance = unsafe { entry.create_instance(&instance_info, None) }
            .map_err(|e| anyhow!("vkCreateInstance failed: {e}; {NO_DEVICE_HELP}"))?;

        let debug_instance =
            has_debug_utils.then(|| ash::ext::debug_utils::Instance::new(&entry, &instance));
        // A fresh create-info: one that went through push_next still points into the
        // instance chain (shared/notes/lavapipe.md, pitfall 3).
        let messenger = match (&debug_instance, options.validation) {
            (Some(d), true) => {
                Some(unsafe { d.create_debug_utils_messenger(&messenger_info(), None) }?)
            }
            _ => None,
        };

        let (physical_device, queue_family, properties) =
            match Self::pick_device(&instance, options) {
                Ok(choice) => choice,
                Err(e) => {
                    unsafe {
                        if let (Some(d), Some(m)) = (&debug_instance, messenger) {
                            d.destroy_debug_utils_messenger(m, None);
                        }
                        instance.destroy_instance(None);
                    }
                    return Err(e);
                }
            };

        let supported = unsafe { instance.get_physical_device_features(physical_device) };
        let features = Features {
            geometry_shader: supported.geometry_shader == vk::TRUE,
            fragment_stores_and_atomics: supported.fragment_stores_and_atomics == vk::TRUE,
            sampler_anisotropy: supported.sampler_anisotropy == vk::TRUE,
            depth_clamp: supported.depth_clamp == vk::TRUE,
        };
        let enabled = vk::PhysicalDeviceFeatures::default()
            .geometry_shader(features.geometry_shader)
            .fragment_stores_and_atomics(features.fragment_stores_and_atomics)
            .sampler_anisotropy(features.sampler_anisotropy)
            .depth_clamp(features.depth_clamp)
            .shader_storage_image_write_without_format(
                supported.shader_storage_image_write_without_format == vk::TRUE,
            )
            // Descriptor arrays indexed by a uniform, non-constant value (material
            // textures, the six directional volumes).
            .shader_sampled_image_array_dynamic_indexing(
                supported.shader_sampled_image_array_dynamic_indexing == vk::TRUE,
            )
            .shader_storage_image_array_dynamic_indexing(
                supported.shader_storage_image_array_dynamic_indexing == vk::TRUE,
            );
        let mut vk12 = vk::PhysicalDeviceVulkan12Features::default().timeline_semaphore(true);
        let mut vk13 = vk::PhysicalDeviceVulkan13Features::default()
            .dynamic_rendering(true)
            .synchronization2(true);
        let priorities = [1.0];
        let queue_infos = [vk::DeviceQueueCreateInfo::default()
            .queue_family_index(queue_family)
            .queue_priorities(&priorities)];
        let mut device_extensions = Vec::new();
        if !options.surface_extensions.is_empty() {
            device_extensions.push(ash::khr::swapchain::NAME.as_ptr());
        }
        let device_info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queue_infos)
            .enabled_features(&enabled)
            .enabled_extension_names(&device_extensions)
            .push_next(&mut vk12)
            .push_next(&mut vk13);
        let device = unsafe { instance.create_device(physical_device, &device_info, None) }
            .context("vkCreateDevice failed")?;
        let queue = unsafe { device.get_device_queue(queue_family, 0) };

        let allocator = Allocator::new(&AllocatorCreateDesc {
            instance: instance.clone(),
            device: device.clone(),
            physical_device,
            debug_settings: Default::default(),
            buffer_device_address: false,
            allocation_sizes: Default::default(),
        })
        .context("creating the GPU memory allocator")?;

        let driver = Self::driver_name(&instance, physical_device, &properties);
        let debug_utils = debug_instance.map(|instance_fns| DebugUtils {
            device: ash::ext::debug_utils::Device::new(&instance, &device),
            instance: instance_fns,
            messenger,
        });
        let context = Arc::new(Self {
            entry,
            instance,
            physical_device,
            device,
            queue,
            queue_family,
            properties,
            driver,
            features,
            allocator: ManuallyDrop::new(Mutex::new(allocator)),
            debug_utils,
            validation_messages,
        });
        log::info!(
            "Vulkan device: {} ({})",
            context.device_name(),
            context.driver
        );
        Ok(context)
    }

    fn pick_device(
        instance: &ash::Instance,
        options: &ContextOptions,
    ) -> Result<(vk::PhysicalDevice, u32, vk::PhysicalDeviceProperties)> {
        let devices = unsafe { instance.enumerate_physical_devices() }
            .map_err(|e| anyhow!("cannot enumerate Vulkan devices: {e}; {NO_DEVICE_HELP}"))?;
        let mut candidates = Vec::new();
        let mut names = Vec::new();
        for device in devices {
            let properties = unsafe { instance.get_physical_device_properties(device) };
            let name = properties
                .device_name_as_c_str()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            names.push(name.clone());
            if let Some(filter) = &options.device {
                if !name.to_lowercase().contains(&filter.to_lowercase()) {
                    continue;
                }
            }
            if properties.api_version < vk::API_VERSION_1_3 {
                log::warn!("skipping {name}: Vulkan 1.3 is required");
                continue;
            }
            let families = unsafe { instance.get_physical_device_queue_family_properties(device) };
            let wanted = vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE;
            let Some(family) = families.iter().position(|f| f.queue_flags.contains(wanted)) else {
                continue;
            };
            candidates.push((
                device_rank(properties.device_type),
                device,
                family as u32,
                properties,
            ));
        }
        candidates.sort_by_key(|c| c.0);
        match candidates.into_iter().next() {
            Some((_, device, family, properties)) => Ok((device, family, properties)),
            None if names.is_empty() => bail!("no Vulkan device found; {NO_DEVICE_HELP}"),
            None => match &options.device {
                Some(filter) => bail!(
                    "no Vulkan 1.3 device matches --device {filter:?}; found: {}",
                    names.join(", ")
                ),
                None => bail!(
                    "no Vulkan 1.3 device with a graphics+compute queue among: {}",
                    names.join(", ")
                ),
            },
        }
    }

    fn driver_name(
        instance: &ash::Instance,
        device: vk::PhysicalDevice,
        properties: &vk::PhysicalDeviceProperties,
    ) -> String {
        let mut driver = vk::PhysicalDeviceDriverProperties::default();
        let mut properties2 = vk::PhysicalDeviceProperties2::default().push_next(&mut driver);
        unsafe { instance.get_physical_device_properties2(device, &mut properties2) };
        let name = driver
            .driver_name_as_c_str()
            .map(|n| n.to_string_lossy().into_owned());
        let info = driver
            .driver_info_as_c_str()
            .map(|n| n.to_string_lossy().into_owned());
        match (name, info) {
            (Ok(name), Ok(info)) if !name.is_empty() => format!("{name} {info}"),
            _ => format!("driver version {:#x}", properties.driver_version),
        }
    }

    pub fn device_name(&self) -> String {
        self.properties
            .device_name_as_c_str()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default()
    }

    /// Warnings and errors the validation layer has reported so far.
    pub fn validation_messages(&self) -> u32 {
        self.validation_messages.load(Ordering::SeqCst)
    }

    pub fn validation_enabled(&self) -> bool {
        self.debug_utils
            .as_ref()
            .is_some_and(|d| d.messenger.is_some())
    }

    /// Names an object for validation messages and GPU profilers.
    pub fn set_name<H: vk::Handle>(&self, handle: H, name: &str) {
        if let Some(debug) = &self.debug_utils {
            let name = CString::new(name).unwrap_or_default();
            let info = vk::DebugUtilsObjectNameInfoEXT::default()
                .object_handle(handle)
                .object_name(&name);
            // A failed name is harmless; don't fail the caller for it.
            let _ = unsafe { debug.device.set_debug_utils_object_name(&info) };
        }
    }

    /// Opens a labelled region in a command buffer (shown by RenderDoc and Nsight).
    pub fn begin_label(&self, cmd: vk::CommandBuffer, name: &str) {
        if let Some(debug) = &self.debug_utils {
            let name = CString::new(name).unwrap_or_default();
            let label = vk::DebugUtilsLabelEXT::default().label_name(&name);
            unsafe { debug.device.cmd_begin_debug_utils_label(cmd, &label) };
        }
    }

    pub fn end_label(&self, cmd: vk::CommandBuffer) {
        if let Some(debug) = &self.debug_utils {
            unsafe { debug.device.cmd_end_debug_utils_label(cmd) };
        }
    }

    pub fn wait_idle(&self) -> Result<()> {
        unsafe { self.device.device_wait_idle() }.context("vkDeviceWaitIdle (device lost?)")
    }
}

impl Drop for Context {
    fn drop(&mut self) {
        unsafe {
            let _ = self.device.device_wait_idle();
            ManuallyDrop::drop(&mut self.allocator);
            self.device.destroy_device(None);
            if let Some(DebugUtils {
                instance,
                messenger: Some(messenger),
                ..
            }) = &self.debug_utils
            {
                instance.destroy_debug_utils_messenger(*messenger, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}

#[cfg(test)]
mod tests {
    /// The host's memory as the rule reads it (sysconf) is what the kernel reports in
    /// /proc/meminfo (MemTotal, in KiB): both count the pages the kernel manages.
    #[cfg(target_os = "linux")]
    #[test]
    fn host_memory_matches_the_kernels_count() {
        let meminfo = std::fs::read_to_string("/proc/meminfo").unwrap();
        let kib: u64 = meminfo
            .lines()
            .find_map(|line| line.strip_prefix("MemTotal:"))
            .and_then(|rest| rest.trim().strip_suffix("kB"))
            .and_then(|n| n.trim().parse().ok())
            .unwrap();
        let bytes = super::host_physical_bytes().unwrap();
        assert!(
            bytes.abs_diff(kib * 1024) < 1 << 20,
            "{bytes} against {kib} KiB"
        );
    }
}
