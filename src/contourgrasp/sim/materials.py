"""What the simulated objects are made of: frictions, density and a typical colour per material.

None of the numbers is measured: each :class:`Material` says its handbook reasoning. Shared by the
YCB objects (:mod:`~contourgrasp.sim.ycb`) and the procedural ones (:mod:`~contourgrasp.sim.procedural`).
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Material:
    """What an object is made of, for the simulation.

    Attributes
    ----------
    friction_hand, friction_table : float
        Sliding friction against the glove and against the table.
    density : float
        kg/m^3 of the object as scanned (a closed outline, so hollow parts count
        their air); used only where the YCB list gives no mass.
    rgba : (4,) float
        A typical colour, for the camera (all differ from the table's beige).
    why : str
        The reasoning behind the numbers (none is measured).
    """

    friction_hand: float
    friction_table: float
    density: float
    rgba: tuple[float, float, float, float]
    why: str


#: Materials of the YCB objects: frictions (not measured: handbook ranges, see each ``why``), density and colour.
MATERIALS = {
    "cardboard": Material(0.55, 0.35, 300.0, (0.78, 0.20, 0.12, 1.0),
                          "printed, varnished paperboard: rubber on paper 0.5-0.6, paper on laminate 0.3-0.4; "
                          "a filled food box weighs ~300 kg/m^3 of its outline"),
    "tinplate": Material(0.55, 0.30, 800.0, (0.70, 0.72, 0.75, 1.0),
                         "lacquered or paper-labelled steel cans, as the thesis's soda can (0.60 / 0.30) with "
                         "a label a bit less grippy than paint; full cans ~800-1000 kg/m^3"),
    "plastic-bottle": Material(0.50, 0.30, 900.0, (0.95, 0.80, 0.10, 1.0),
                               "smooth HDPE/PET bottles, as the thesis's bottle (0.50 / 0.30); full ~900 kg/m^3"),
    "hard-plastic": Material(0.50, 0.30, 600.0, (0.20, 0.45, 0.85, 1.0),
                             "moulded ABS/PP (dishes, toys, tool handles): rubber on smooth plastic 0.4-0.6, "
                             "plastic on laminate 0.25-0.35; hollow moulded parts (a Duplo brick, a toy's "
                             "part) ~600 kg/m^3 of their outline, a guess from ABS's 1050 and their thin walls"),
    "plastic-fruit": Material(0.65, 0.45, 300.0, (0.85, 0.35, 0.10, 1.0),
                              "the YCB fruits are soft PVC replicas (the YCB list: 'plastic apple'), matte and a "
                              "little tacky: grips rubber better than hard plastic, 0.6-0.7; hollow"),
    "wood": Material(0.60, 0.45, 600.0, (0.80, 0.62, 0.38, 1.0),
                     "planed or painted wood: rubber on wood 0.6-0.8 (low end for paint), wood on laminate "
                     "0.4-0.5; pine/beech 450-700 kg/m^3"),
    "foam": Material(0.90, 0.70, 40.0, (0.95, 0.55, 0.15, 1.0),
                     "polyurethane foam and sponge: soft, high-hysteresis contact, 0.8-1.0 against rubber; "
                     "~20-60 kg/m^3"),
    "rubber": Material(0.90, 0.70, 500.0, (0.15, 0.30, 0.80, 1.0),
                       "a hollow rubber ball (racquetball): rubber on rubber ~1, on laminate 0.6-0.8"),
    "leather": Material(0.60, 0.45, 450.0, (0.92, 0.92, 0.88, 1.0),
                        "stitched leather balls (softball, baseball): rubber on leather 0.5-0.7"),
    "felt": Material(0.70, 0.50, 370.0, (0.80, 0.90, 0.20, 1.0),
                     "the tennis ball's felt: fibrous, 0.6-0.8 against rubber, ~0.5 on laminate"),
    "steel": Material(0.45, 0.25, 7800.0, (0.55, 0.55, 0.58, 1.0),
                      "bare or plated steel and brass: rubber on smooth metal 0.4-0.6, metal on laminate 0.2-0.3"),
    "glass": Material(0.45, 0.25, 2500.0, (0.30, 0.70, 0.60, 1.0),
                      "smooth soda-lime glass (marbles, the lid): 0.4-0.5 against rubber, ~0.25 on laminate"),
    "stone": Material(0.70, 0.50, 2700.0, (0.45, 0.42, 0.38, 1.0),
                      "rough stone against rubber 0.6-0.8, against wood ~0.5 (the thesis's stones); granite "
                      "~2700 kg/m^3"),
}
