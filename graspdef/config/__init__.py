"""The one TOML reader (see :mod:`graspdef.config.reader`): ``read_toml(path)`` -> :class:`Table`,
whose ``check(accepted, required)`` rejects unknown keys by name (did-you-mean, accepted keys
listed) and whose typed getters (number, integer, boolean, string from a set, vector, list,
quantity with a dimension) raise :class:`~graspdef.errors.ConfigError` naming file, table and key."""
from .reader import REQUIRED, Table, check_names, closest, parse_toml, read_toml, unknown_name

__all__ = ["REQUIRED", "Table", "check_names", "closest", "parse_toml", "read_toml", "unknown_name"]
