"""Ways into a shop: the settings lookup shared by the plain filter and the
LinuxCNC filter (`config`), and the LinuxCNC `[FILTER]` program (`linuxcnc`)."""
