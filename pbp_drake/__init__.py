"""pbp_drake: Policy Blending with Primitives (PBP) for shared control, on Drake.

The math lives in `pbp_drake.core` (NumPy only); the Drake systems in `pbp_drake.systems`;
`pbp_drake.builder.build_diagram` turns a scenario file into a Diagram.
"""

__version__ = "0.1.0"
