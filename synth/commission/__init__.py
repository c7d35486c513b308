"""Virtual commissioning: synth's plant automaton drives a real PLC runtime over Modbus TCP or OPC UA (docs/commissioning.md).

The I/O maps and layouts (``iomap``), the device under test CI runs (``device``), the
protocol clients behind one interface (``links``), the closed loop (``loop``), faults and
coverage.
"""
