"""tensor-servo: bit-accurate model and tools of the tensor-servo FPGA kinematic servo core.

Modules:
  chain      chain description (JSON), validation
  robots     embedded example chains
  urdf, dh   importers
  reference  float reference (numpy): FK, Jacobian by screw transport, forward velocity problem
  model      the C++ bit-accurate model through its Python bindings (_model)
  cli        the ``tservo`` command
"""
__version__ = "0.1.0"
