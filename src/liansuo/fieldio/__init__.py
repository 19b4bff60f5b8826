"""Field I/O: the interlocking driving trackside equipment over Modbus TCP, and the field simulator that serves the
simulated equipment the same way (docs/field-mode.md). Between the simulation and its front ends: the point map,
the frames on the wire, the interlocking's link and the field simulator's server. ``pymodbus`` is the ``field``
extra: only the link and the server import it."""
