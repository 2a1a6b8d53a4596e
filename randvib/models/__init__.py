"""Model families: the device (Harvester), friction laws, excitations, presets."""
