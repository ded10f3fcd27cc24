"""Built-in examples: ordinary TOML case files shipped with the package, and Python builders
of the same models for tests, benchmarks and notebooks."""

from pathlib import Path

EXAMPLES_DIR = Path(__file__).parent


def example_path(name: str) -> Path:
    """Path of the shipped case file ``NAME.toml``."""
    return EXAMPLES_DIR / f"{name}.toml"
