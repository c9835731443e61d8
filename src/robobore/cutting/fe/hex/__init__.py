"""The hexahedral (3D) engine's element and scalar functions: the 8-node hexahedron
(:mod:`.element`) and the 3D state layout with the node, contact and tool updates
(:mod:`.scalar3d`)."""
