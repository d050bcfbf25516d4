"""The layout of microg.models and microg.structure: public names and one frame class.

References: the public names of these modules before they were split into one concept each,
which must still import from the same paths; the modules' own source, read as syntax trees.
Import cycles and module size are checked for the whole package by tests/test_package_layout.py.
"""

from __future__ import annotations

import ast
import importlib
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[2] / "src"

#: the public names of each module before the split (nastran's CoordSystem excepted: the
#: one coordinate-system class is microg.models.coords.CoordinateFrame)
PUBLIC_NAMES: dict[str, tuple[str, ...]] = {
    "microg.models.bdf": (
        "Card",
        "IGNORED_CARDS",
        "MAX_CARDS",
        "MAX_INCLUDE_DEPTH",
        "SECTION_SHEAR_FACTORS",
        "SUPPORTED_CARDS",
        "grid_geometry",
        "load_bdf",
        "read_cards",
    ),
    "microg.models.build": (
        "Builder",
        "build_station",
    ),
    "microg.models.catalog": (
        "shipped_model_text",
        "shipped_models",
    ),
    "microg.models.graph": (
        "BASIC",
        "BeamElement",
        "BeamSection",
        "COMPONENTS",
        "ConcentratedMass",
        "Constraint",
        "CoordinateFrame",
        "FRAME_KINDS",
        "GraphModel",
        "GraphPoint",
        "Interpolation",
        "MASS_FORMULATIONS",
        "MAX_GRAPH_ITEMS",
        "Node",
        "RigidLink",
        "RodElement",
        "ScalarSpring",
        "Spring",
        "dump_graph",
        "load_graph",
        "loads_graph",
        "parse_components",
        "validate_graph",
    ),
    "microg.models.load": (
        "MODEL_SUFFIXES",
        "load_model",
        "loads_station",
    ),
    "microg.models.messages": (
        "EXAMPLES",
        "fail",
        "loc_path",
        "short",
        "structure_error",
        "toml_repr",
        "toml_string",
    ),
    "microg.models.modal": (
        "FORMAT",
        "FORMAT_VERSION",
        "MAX_GRIDS",
        "MAX_MODES",
        "ModalModel",
        "ModalPoint",
        "ModelOptions",
        "POINT_KINDS",
        "RIGID_GAP",
        "RIGID_TOL",
        "ReplacedRigid",
        "UnitSystem",
        "load_modal_model",
        "nearest_ids",
        "parse_grid",
        "parse_units",
        "read_options",
        "replace_rigid_modes",
        "rigid_basis_at",
        "save_modal_model",
        "shift_rigid_mass",
    ),
    "microg.models.nastran": (
        "EXTRA_HINT",
        "Op2File",
        "Op2Modes",
        "Op4Model",
        "modal_model_from_op2",
        "modal_model_from_op4",
        "read_op2_modes",
        "read_op4",
    ),
    "microg.models.schema": (
        "BeamIn",
        "BeamMassIn",
        "BodyIn",
        "BodyMassIn",
        "EARTH_RADIUS",
        "FIELD_LIMITS",
        "FileIn",
        "HILL_RADIUS",
        "InertiaIn",
        "Limit",
        "MAX_COUNTS",
        "MAX_NAME",
        "MAX_TEXT",
        "MIN_BEAM_LENGTH",
        "MIN_MASS",
        "MassIn",
        "ON_AXIS_TOL",
        "OrbitIn",
        "PointIn",
        "StationIn",
        "UNIT_SYSTEMS",
    ),
    "microg.models.station": (
        "Beam",
        "NamedPoint",
        "Orbit",
        "POLAR_GYRATION_FRACTION",
        "PointMass",
        "RigidBody",
        "Station",
    ),
    "microg.models.toml": (
        "EARTH_RADIUS",
        "MAX_FILE_BYTES",
        "MAX_KEY_PARTS",
        "MAX_NESTING",
        "ON_AXIS_TOL",
        "UNIT_SYSTEMS",
        "dump_station",
        "load_station",
        "loads_station",
        "shipped_models",
    ),
    "microg.models.uff": (
        "UffDataset",
        "data_values",
        "dataset_units",
        "modal_model_from_uff",
        "read_uff",
        "write_uff_modes",
        "write_uff_time",
    ),
    "microg.structure": (
        "PointMap",
        "Structure",
    ),
    "microg.structure.discretize": (
        "DEFAULT_ELEMENTS",
        "DEFAULT_FUNCTIONS",
        "METHODS",
        "PLANES",
        "discretize",
    ),
    "microg.structure.fem": (
        "AXIAL_PENALTY",
        "DEFAULT_ELEMENTS_PER_BEAM",
        "DOF_NAMES",
        "FrameStructure",
        "FrameTree",
        "GJ_ZERO_FRACTION",
        "INERTIA_ZERO_FRACTION",
        "MAX_FEM_DOF",
        "MAX_STIFFNESS_RATIO",
        "NodeSamples",
        "POLAR_GYRATION_FRACTION",
        "TORSION_PENALTY",
        "build_fem",
        "cantilever_flexibility_local",
        "check_rotary_inertia",
        "check_stiffness_contrast",
        "constrain",
        "frame_mass_local",
        "frame_rotation",
        "frame_stiffness_local",
        "point_mass_matrix",
        "rigid_link",
        "torsion_is_rigid",
    ),
    "microg.structure.frame": (
        "AXIAL_PENALTY",
        "CONDENSE_MAX",
        "DEFAULT_ELEMENTS_PER_BEAM",
        "DOF_NAMES",
        "FrameMatrices",
        "FrameSamples",
        "GJ_ZERO_FRACTION",
        "MAX_FEM_DOF",
        "StationMesh",
        "TORSION_PENALTY",
        "assemble_frame",
        "beam_mass_consistent_local",
        "beam_mass_lumped_local",
        "beam_stiffness_local",
        "build_frame",
        "bush_matrix",
        "frame_mass_local",
        "frame_rotation",
        "frame_stiffness_local",
        "graph_from_station",
        "interpolation_matrix",
        "mass_properties_of",
        "mesh_station",
        "point_mass_matrix",
        "release_ends",
        "rigid_link",
        "rod_mass_local",
        "rod_stiffness_local",
        "shear_parameter",
        "torsion_is_rigid",
    ),
    "microg.structure.modal": (
        "GRID_COMPONENT",
        "GridPointMaps",
        "ModalSamples",
        "RIGID_FIT_GRIDS",
        "modal_structure",
        "rigid_coefficients",
    ),
    "microg.structure.ritz": (
        "Coordinate",
        "MAX_FUNCTIONS",
        "MAX_RITZ_BEAMS",
        "PLANES",
        "assemble",
        "build_ritz",
        "cantilever_functions",
        "clamped_linear_functions",
        "gravity_gradient_stiffness",
        "planar_coordinates",
        "point_maps",
        "report_cantilever_function",
        "sample_points",
        "spatial_coordinates",
    ),
    "microg.structure.structure": (
        "PointMap",
        "Structure",
    ),
}


def _modules() -> dict[str, tuple[Path, bool]]:
    out = {}
    for p in (SRC / "microg").rglob("*.py"):
        parts = list(p.relative_to(SRC).with_suffix("").parts)
        package = parts[-1] == "__init__"
        out[".".join(parts[:-1] if package else parts)] = (p, package)
    return out


@pytest.mark.parametrize("module", sorted(PUBLIC_NAMES))
def test_public_names_still_import_from_their_module(module):
    mod = importlib.import_module(module)
    missing = [n for n in PUBLIC_NAMES[module] if not hasattr(mod, n)]
    assert missing == []
    assert set(PUBLIC_NAMES[module]) <= set(getattr(mod, "__all__", PUBLIC_NAMES[module]))


def test_one_coordinate_system_class():
    # every class with a to_basic method in microg.models is the one frame class
    owners = set()
    for m, (p, _) in _modules().items():
        if m.startswith("microg.models"):
            for node in ast.walk(ast.parse(p.read_text(encoding="utf-8"))):
                if isinstance(node, ast.ClassDef) and any(
                    isinstance(b, ast.FunctionDef) and b.name == "to_basic" for b in node.body
                ):
                    owners.add(f"{m}.{node.name}")
    assert owners == {"microg.models.coords.CoordinateFrame"}
