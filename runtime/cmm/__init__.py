"""CMM capabilities on a loaded model: volumetric error maps over the working volume, space and
face diagonals, squareness from straightness reference lines, and Pahk's example error sets.
"""

