"""What the machine can hold (fretwear.resources): the memory it reports and the refusal of
a size that cannot fit.

References: the kernel's own figure (/proc/meminfo, read here independently of the
``os.sysconf`` call under test) and the documented rule (refuse above ``fraction`` of the
memory; never refuse when the machine does not say).
"""

from pathlib import Path

import pytest

from fretwear import resources
from fretwear.errors import InputError


def test_machine_memory_is_the_kernels_total():
    """``SC_PHYS_PAGES x SC_PAGE_SIZE`` against MemTotal of /proc/meminfo: MemTotal leaves
    out the memory the kernel reserves at boot (a few per cent at most), hence 10 %."""
    meminfo = Path("/proc/meminfo")
    if not meminfo.is_file():
        pytest.skip("no /proc/meminfo on this system")
    line = next(ln for ln in meminfo.read_text().splitlines() if ln.startswith("MemTotal:"))
    total = int(line.split()[1]) * 1024
    assert resources.machine_memory() == pytest.approx(total, rel=0.1)


def test_gib_in_messages():
    """Binary gigabytes, three significant digits (exact strings)."""
    assert resources.gib(2**30) == "1 GiB"
    assert resources.gib(1.5 * 2**30) == "1.5 GiB"
    assert resources.gib(123.456 * 2**30) == "123 GiB"


def test_require_memory_refuses_beyond_the_fraction_only(monkeypatch):
    """On a machine of 2 GiB the default fraction 0.9 lets 1.8 GiB through and refuses just
    above it, in one message with both figures; a machine that does not say (0) refuses
    nothing. Exact: one comparison with fraction x total."""
    monkeypatch.setattr(resources, "machine_memory", lambda: 2 * 2**30)
    resources.require_memory(0.9 * 2 * 2**30, "a mesh")
    resources.require_memory(2 * 2**30, "a mesh", fraction=1.0)
    with pytest.raises(InputError, match=r"a mesh needs about 1.8 GiB of memory; this machine "
                                         r"has 2 GiB: make it smaller"):
        resources.require_memory(0.9 * 2 * 2**30 * (1 + 1e-9), "a mesh")
    monkeypatch.setattr(resources, "machine_memory", lambda: 0)
    resources.require_memory(1e30, "a mesh")
