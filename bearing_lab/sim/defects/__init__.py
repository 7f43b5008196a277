"""Local defects on raceways: description, exact contact geometry, contact tables.

Public API
----------
Defect            -- frozen dataclass: outline (rectangle, ellipse, polygon), depth, position.
rigid_drop        -- how far a rigid ball centred over a defect moves before it touches (m).
contact_table     -- tabulated ball-race contact G(psi, delta) with F = K_hertz * G.
ContactTable      -- the table: psi, delta, G, drop, intact_fraction, model, race.
RaceGeometry      -- exact torus groove of one race and the ball-race gap function.
CONTACT_MODELS    -- name -> ContactModel: "profile", "drop", "area", "halfspace".

Modules: model (Defect), geometry (exact sphere-torus gap, rigid drop), contact (tables
and the models), halfspace (elastic half-space contact solver behind the default
"halfspace" model; halfspace_skewed for a rectangle skewed to the track), _table_cache (the
on-disk table cache), _halfspace_kernels (numba steps of the solver), compare_law (the local law
against the half-space, a check).
"""
from .model import Defect
from .geometry import RaceGeometry, rigid_drop
from .contact import CONTACT_MODELS, ContactTable, contact_table

__all__ = ["Defect", "RaceGeometry", "rigid_drop", "contact_table", "ContactTable",
           "CONTACT_MODELS"]
