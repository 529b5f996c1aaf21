// placeholder: the Vulkan driver is being written
