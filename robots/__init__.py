"""Robot presets shipped as data (one TOML file per robot); installed as ``gb_pin.presets``."""
