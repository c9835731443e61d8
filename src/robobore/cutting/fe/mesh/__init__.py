"""The workpiece meshes: the graded quadrilateral mesh of orthogonal cutting
(:mod:`.orthogonal`) and the hexahedral bore-wall mesh of the 3D boring model
(:mod:`.boring3d`)."""
