"""The bolted lap joint of docs/tutorial.md (2D, 60 x 4 mm steel plates overlapping 30 mm, the
bolt's 20 MPa over 10 mm of the overlap, a 10 kPa transverse shaker on the upper plate), and
its resonance with harmonics 0-3 and 64 samples, as the tutorial's sweep finds it."""

import fretwear as fw
from fretwear.model import join

#: the tutorial's resonance [Hz]: the peak of its 26-point sweep over 400-1400 Hz (measured)
F_PEAK = 1117.7344613099897
#: the first-harmonic amplitude of the joint's y displacement there [m], from that sweep
#: (every point warm-started from its neighbour; the version before the first-harmonic
#: start of three-harmonic solves, which reached it by continuation from 400 Hz)
AMPLITUDE_AT_PEAK = 5.413350036853035e-05


def tutorial_joint():
    """The model of docs/tutorial.md, section 2 (same calls)."""
    lower = fw.rectangle(0.060, 0.004, nx=30, ny=2)
    upper = fw.rectangle(0.060, 0.004, nx=30, ny=2, origin=(0.030, 0.004))
    mesh = join(("lower", lower), ("upper", upper))
    return fw.from_mesh(
        mesh, fw.Material(E=210e9, nu=0.3, rho=7800.0), thickness=0.020,
        damping=fw.Damping(loss_factor=0.002),
        supports=[("lower.left", "all"), ("upper.right", "all")],
        loads=[fw.Traction("upper.top", pressure=20e6, region={"x": (0.040, 0.050)},
                           name="bolt"),
               fw.Traction("upper.top", traction=(0.0, -1e4), waveform="cos",
                           name="shaker")],
        contact=fw.ContactSpec("upper.bottom", region={"x": (0.030, 0.060)},
                               partner="lower.top", mu=0.3, wear_coefficient=1e-14,
                               partner_wear_coefficient=1e-14),
        observed={"joint": (0.045, 0.008)})
