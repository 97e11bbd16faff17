"""Reading and writing: path files, exports."""

from .paths import read_path_csv, write_path_csv

__all__ = ["read_path_csv", "write_path_csv"]
