"""Arbitrary Lagrangian-Eulerian mesh motion of the plane-strain engine: the tool-frame ALE pass
(:mod:`.rezone`), its host-side stencil (:mod:`.stencils`), the donor-cell remap
(:mod:`.remap`) and the tool-frame mesh that travels with the tool (:mod:`.toolframe`)."""
