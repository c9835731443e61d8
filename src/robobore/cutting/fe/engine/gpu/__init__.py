"""The GPU engines (numba-cuda), compiled from the CPU engines' scalar functions: the shared CUDA
plumbing (:mod:`.shared`), the 2D engine (:mod:`.backend2d` with its device functions
:mod:`.device2d` and kernels :mod:`.kernels2d`) and the 3D engine (:mod:`.backend3d`, kernels
:mod:`.kernels3d`)."""
