"""Splits a vector into consecutive pieces, recomputed only when the input changes."""

from pydrake.systems.framework import LeafSystem


class VectorSplit(LeafSystem):
    """Drake's Demultiplexer, with outputs that depend on the input alone.

    .. pydrake_system::

        name: VectorSplit
        input_ports:
        - u
        output_ports:
        - y0
        - ...

    Output `i` is the `sizes[i]` entries of `u` after those of the outputs before it.
    Drake's Demultiplexer declares no narrower dependency than every source of the diagram,
    so a plant stepping at 5 ms made every Python system downstream of it (the blender, the
    DMP bank's consumers) recompute at each plant step although its input, held between
    control ticks, had not changed.
    """

    def __init__(self, sizes):
        super().__init__()
        sizes = [int(size) for size in sizes]
        if not sizes or min(sizes) < 1:
            raise ValueError(f"sizes must be positive integers, got {sizes}")
        self._input_port = self.DeclareVectorInputPort("u", sum(sizes))
        start = 0
        for index, size in enumerate(sizes):
            self.DeclareVectorOutputPort(
                f"y{index}", size,
                lambda context, output, piece=slice(start, start + size):
                    output.SetFromVector(self._input_port.Eval(context)[piece]),
                prerequisites_of_calc={self._input_port.ticket()})
            start += size

    def get_input_port(self):
        return self._input_port
