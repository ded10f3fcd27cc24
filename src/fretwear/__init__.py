"""fretwear: coupled vibration and fretting wear of frictional contact interfaces.

Implements the "DLFT with wear" method of Salles, Blanc, Thouverez and Gousskov (2011),
Int. J. Solids Struct. 48, 1513-1524, and goes beyond it (3D contact, continuation, adaptive
slow-time steps, time-domain reference solvers).
"""

__version__ = "0.1.0"
