"""The explicit time integration shared by the models: the index layout of the small state arrays
(:mod:`.layout`), the state of the plane-strain (:mod:`.state2d`) and hexahedral
(:mod:`.state3d`) engines, their compiled CPU loops (:mod:`.chunk_loop`, :mod:`.kernels3d`), the
end of a step both engines share on both devices (:mod:`.history`),
the 2D kernels' names in one place (:mod:`.kernels`), the host driver of the loops
(:mod:`.chunk_driver`, :mod:`.threads`, :mod:`.status`) and the CUDA engines (:mod:`.gpu`)."""
