#!/usr/bin/env python3
"""Runs the rbdem binary on every bad input we know of and checks that each is refused cleanly: exit status 2
(bad input), no crash, and a message that names the input (the key, option or file) and says what to do.
Writes the Markdown table of inputs and messages and fails when docs/bad_inputs.md differs from it.

    tests/bad_inputs.py --rbdem build/bin/rbdem --work build/bad_inputs        # the CTest test
    RBDEM_UPDATE_DOCS=1 tests/bad_inputs.py --rbdem build/bin/rbdem --work build/bad_inputs   # refresh the page

Each case runs in --work with relative file names, so the messages (and the page) do not depend on the machine.
"""
import argparse
import difflib
import os
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.dirname(HERE)
DATA = os.path.join(HERE, "data", "bad_inputs")

# Scene files written into the work folder: name -> TOML text.
SCENES = {
    "syntax.toml": "[rock]\ncohesion = = 3e6\n",
    "unclosed.toml": "[rock\ncohesion = 3e6\n",
    "typo_key.toml": "[rock]\ncohesoin = 3e6\n",
    "unknown_section.toml": "[specimens]\nwidth = 0.05\n",
    "no_section.toml": "width = 0.05\n",
    "string_number.toml": "[joint_set]\nspacing = \"10 mm\"\n",
    "number_bool.toml": "[joint_set]\nenabled = 1\n",
    "real_integer.toml": "[numerics]\nthreads = 2.5\n",
    "table_value.toml": "[rock.effective_modulus]\nvalue = 160e9\n",
    "array_value.toml": "[mesh]\nsize = [0.001, 0.002]\n",
    "nan.toml": "[rock]\ndensity = nan\n",
    "zero_modulus.toml": "[rock]\neffective_modulus = 0\n",
    "negative_modulus.toml": "[joint]\neffective_modulus = -50e9\n",
    "zero_strength.toml": "[rock]\ntensile_strength = 0.0\n",
    "negative_cohesion.toml": "[joint]\ncohesion = -1e6\n",
    "zero_density.toml": "[rock]\ndensity = 0\n",
    "zero_thickness.toml": "[specimen]\nthickness = 0\n",
    "negative_width.toml": "[specimen]\nwidth = -0.05\n",
    "zero_spacing.toml": "[joint_set]\nspacing = 0\n",
    "friction_90.toml": "[rock]\nfriction_deg = 90\n",
    "joint_friction_120.toml": "[joint]\nfriction_deg = 120\n",
    "dip_negative.toml": "[joint_set]\ndip_deg = -15\n",
    "dip_120.toml": "[joint_set]\ndip_deg = 120\n",
    "fine_spacing.toml": "[joint_set]\nspacing = 0.0015\n[mesh]\nsize = 0.001\n",
    "coarse_mesh.toml": "[mesh]\nsize = 0.2\n",
    "modulus_in_gpa.toml": "[rock]\neffective_modulus = 160   # GPa meant; the file is in Pa\n",
    "strength_in_kpa.toml": "[joint]\neffective_modulus = 5e6\ncohesion = 3.36e9\n",
    "scene_in_mpa.toml": "[rock]\neffective_modulus = 20000\ntensile_strength = 6\ncohesion = 6\n",
    "bad_model.toml": "[specimen]\nmodel = \"plain_strain\"\n",
    "negative_seed.toml": "[mesh]\nseed = -1\n",
    "realizations_zero.toml": "[study]\ndips = [60]\nrealizations = 0\n",
    "realizations_real.toml": "[study]\ndips = [60]\nrealizations = 2.5\n",
    "one_dip.toml": "[study]\ndips = [60]\n",
    "rock2_missing_layer.toml": "[rock2]\ngroups = \"sandstone\"\n",
    "joint2_missing_curve.toml": "[joint2]\ngroups = \"fault\"\n",
    "rock2_layer_at_90.toml": "[joint_set]\ndip_deg = 90\n[rock2]\ngroups = \"layer_1, layer_11\"\n",
    "beds_unknown_rock.toml": "[beds]\npattern = [\"rock\", \"shale\"]\n",
    "beds_and_groups.toml": "[rock2]\ngroups = \"layer_1\"\n[beds]\npattern = [\"rock\", \"rock2\"]\n",
    "beds_thickness_count.toml": "[beds]\npattern = [\"rock\", \"rock2\"]\nthickness = [0.01]\n",
    "short_bridges.toml": "[joint_set]\npersistence = 0.95\njoint_length = 0.01\n",
    "persistence_zero.toml": "[joint_set]\npersistence = 0\n",
    "dip2_200.toml": "[joint_set2]\nenabled = true\ndip_deg = 200\n",
}

# (input tried, command line after `rbdem`, text the message must contain: the name of the input)
CASES = [
    # --- scene files: TOML and keys
    ("malformed TOML (`= =`)", "mesh syntax.toml", "syntax.toml:2"),
    ("malformed TOML (unclosed `[rock`)", "mesh unclosed.toml", "unclosed.toml:1"),
    ("misspelt key `rock.cohesoin`", "mesh typo_key.toml", "rock.cohesoin"),
    ("unknown section `[specimens]`", "mesh unknown_section.toml", "specimens.width"),
    ("key outside any section", "mesh no_section.toml", "width"),
    ("string for a number", "mesh string_number.toml", "joint_set.spacing"),
    ("number for a boolean", "mesh number_bool.toml", "joint_set.enabled"),
    ("real for an integer", "mesh real_integer.toml", "numerics.threads"),
    ("table for a number", "mesh table_value.toml", "rock.effective_modulus"),
    ("array for a number", "mesh array_value.toml", "mesh.size"),
    ("not-a-number value", "mesh nan.toml", "rock.density"),
    ("choice not in the list", "mesh bad_model.toml", "specimen.model"),
    ("missing scene file", "mesh missing.toml", "missing.toml"),
    ("scene path is a folder", "mesh folder", "folder"),
    # --- values
    ("zero rock modulus", "mesh zero_modulus.toml", "rock.effective_modulus"),
    ("negative joint modulus", "mesh negative_modulus.toml", "joint.effective_modulus"),
    ("zero tensile strength", "mesh zero_strength.toml", "rock.tensile_strength"),
    ("negative joint cohesion", "mesh negative_cohesion.toml", "joint.cohesion"),
    ("zero density", "mesh zero_density.toml", "rock.density"),
    ("zero thickness", "mesh zero_thickness.toml", "specimen.thickness"),
    ("negative width", "mesh negative_width.toml", "specimen.width"),
    ("zero spacing", "mesh zero_spacing.toml", "joint_set.spacing"),
    ("negative spacing (`--spacing`)", "mesh --spacing -0.01", "--spacing"),
    ("rock friction angle 90 deg", "mesh friction_90.toml", "rock.friction_deg"),
    ("joint friction angle 120 deg", "mesh joint_friction_120.toml", "joint.friction_deg"),
    ("dip -15 deg", "mesh dip_negative.toml", "joint_set.dip_deg"),
    ("dip 120 deg", "mesh dip_120.toml", "joint_set.dip_deg"),
    ("dip 95 deg (`--beta`)", "mesh --beta 95", "--beta"),
    ("spacing under two mesh sizes", "mesh fine_spacing.toml", "joint_set.spacing"),
    ("mesh size larger than the specimen", "mesh coarse_mesh.toml", "mesh.size"),
    ("modulus in GPa", "mesh modulus_in_gpa.toml", "rock.effective_modulus"),
    ("a scene written in MPa", "mesh scene_in_mpa.toml", "rock.effective_modulus"),
    ("confining pressure in MPa", "triaxial --confining 10", "loading.confining_pressure"),
    ("joint cohesion above the joint modulus", "mesh strength_in_kpa.toml", "joint.effective_modulus"),
    ("strength above the modulus by `--set`", "ucs --set rock.cohesion=200e9", "rock.cohesion"),
    ("negative mesh seed", "mesh negative_seed.toml", "mesh.seed"),
    ("mesh seed that is not a whole number", "mesh --set mesh.seed=1.5", "mesh.seed"),
    ("mesh seed with a user mesh", "mesh --mesh good_square.msh --set mesh.seed=3", "mesh.seed"),
    # --- several joint sets and materials
    ("second rock named for a layer the mesh lacks", "mesh rock2_missing_layer.toml", "rock2.groups"),
    ("second joint named for a curve the mesh lacks", "mesh joint2_missing_curve.toml", "joint2.groups"),
    ("second rock by a layer number the 90 deg mesh lacks", "mesh rock2_layer_at_90.toml", "joint_set.dip_deg = 90"),
    ("beds naming a rock the scene lacks", "mesh beds_unknown_rock.toml", "beds.pattern"),
    ("second rock placed by layer and by beds", "mesh beds_and_groups.toml", "rock2.groups"),
    ("one bed thickness for two beds", "mesh beds_thickness_count.toml", "beds.thickness"),
    ("rock bridges shorter than two elements", "mesh short_bridges.toml", "joint_set.joint_length"),
    ("persistence 0 (no joints: use enabled = false)", "mesh persistence_zero.toml", "joint_set.persistence"),
    ("second set dipping 200 deg", "mesh dip2_200.toml", "joint_set2.dip_deg"),
    ("persistence with a user mesh", "mesh --mesh good_square.msh --set joint_set.persistence=0.5",
     "joint_set.persistence"),
    # --- 3D scenes (specimen.dimension = 3)
    ("a 3D disc thinner than one tetrahedron",
     "mesh --set specimen.dimension=3 --set specimen.shape=disc --set specimen.thickness=0.002",
     "specimen.thickness"),
    ("a 3D full disc in the Brazilian test", "brazilian --set specimen.dimension=3 --set specimen.contact_arc_deg=0",
     "specimen.contact_arc_deg"),
    ("a 3D scene with non-persistent joints", "mesh --set specimen.dimension=3 --set joint_set.persistence=0.5",
     "joint_set.persistence"),
    ("a 3D scene with a scattered bond stiffness (2D only)",
     "mesh --set specimen.dimension=3 --set rock.stiffness_weibull_modulus=3", "rock.stiffness_weibull_modulus"),
    ("a 3D scene with a 2D user mesh (no tetrahedra)", "mesh --set specimen.dimension=3 --mesh good_square.msh",
     "good_square.msh"),
    ("`mesh --out` of a 3D scene", "mesh --set specimen.dimension=3 --out cylinder.msh", "--out"),
    ("a dip direction in 2D", "mesh --set joint_set.dip_direction_deg=30", "joint_set.dip_direction_deg"),
    ("dimension 4", "mesh --set specimen.dimension=4", "specimen.dimension"),
    # --- the direct shear test: one horizontal joint
    ("`shear` of a dipping joint", "shear --set joint_set.dip_deg=30", "joint_set.dip_deg"),
    ("`shear` with joints 10 mm apart (several planes)", "shear --set joint_set.spacing=0.01", "joint_set.spacing"),
    ("`shear` of a disc", "shear --set specimen.shape=disc", "specimen.shape"),
    ("`shear` of a softening joint", "shear --set joint.fracture_energy=5", "joint.fracture_energy"),
    ("`shear` without joints", "shear --set joint_set.enabled=false", "joint_set.enabled"),
    ("`shear` with a negative normal stress", "shear --normal-stress -1e6", "normal"),
    # --- studies with realizations
    ("no realizations in a study", "sweep realizations_zero.toml", "study.realizations"),
    ("realizations not a whole number", "sweep realizations_real.toml", "study.realizations"),
    ("`sweep --realizations 0`", "sweep one_dip.toml --realizations 0", "realizations = 0"),
    ("`--realizations 0` of the default study", "--realizations 0", "realizations = 0"),
    ("`--realizations` with a command", "ucs --realizations 3", "--realizations"),
    # --- command line
    ("`--set` without `=`", "mesh --set rock.cohesion", "rock.cohesion"),
    ("`--set` with an empty value", "mesh --set rock.cohesion=", "rock.cohesion"),
    ("`--set` of an unknown key", "mesh --set rock.modulus=1e9", "rock.modulus"),
    ("`--set` with a unit", "mesh --set joint_set.spacing=10mm", "joint_set.spacing"),
    ("unknown option", "ucs --bta 60", "--bta"),
    ("option without its value", "ucs --beta", "--beta"),
    ("unknown command", "ucss", "ucss"),
    ("sweep without its study file", "sweep", "study"),
    ("cycles unloading above their first level", "cyclic --set loading.cycle_unload_stress=5e6",
     "loading.cycle_unload_stress"),
    ("a hold below the confining pressure", "hold --confining 20e6 --hold-stress 10e6", "loading.hold_stress"),
    ("missing study file", "sweep missing_study.toml", "missing_study.toml"),
    ("missing calibration file", "calibrate missing_targets.toml", "missing_targets.toml"),
    # --- user meshes (--mesh)
    ("mesh file missing", "mesh --mesh missing.msh", "missing.msh"),
    ("empty mesh file", "mesh --mesh empty.msh", "empty.msh"),
    ("text file, not a mesh", "mesh --mesh not_a_mesh.msh", "not_a_mesh.msh"),
    ("gmsh .geo script named .msh", "mesh --mesh script.msh", "script.msh"),
    ("truncated .msh", "mesh --mesh truncated.msh", "truncated.msh"),
    ("element on a node the file lacks (crashed gmsh 4.8)", "mesh --mesh missing_node.msh", "missing_node.msh"),
    ("node line with a number too many (crashed gmsh 4.8)", "mesh --mesh node_line.msh", "node_line.msh"),
    ("physical name of dimension 7 (crashed gmsh 4.8)", "mesh --mesh physical_dim.msh", "physical_dim.msh"),
    ("header declaring 86 540 488 nodes for 4 (gmsh 4.8 allocated 1.4 GB)", "mesh --mesh node_count.msh",
     "node_count.msh"),
    ("$Entities header declaring 12 372 285 entities for 1 (gmsh 4.8 allocated 1.6 GB)",
     "mesh --mesh entity_count.msh", "entity_count.msh"),
    ("a section rbdem does not read ($NodeData)", "mesh --mesh node_data.msh", "node_data.msh"),
    ("no physical groups", "mesh --mesh no_physical.msh", "no_physical.msh"),
    ("quadrangles", "mesh --mesh quads.msh", "quads.msh"),
    ("second-order triangles", "mesh --mesh second_order.msh", "second_order.msh"),
    ("zero-area triangle", "mesh --mesh degenerate.msh", "degenerate.msh"),
    ("duplicate nodes", "mesh --mesh duplicate_nodes.msh", "duplicate_nodes.msh"),
    ("T-junction (non-conforming)", "mesh --mesh t_junction.msh", "t_junction.msh"),
    ("3D: a node off the plane", "mesh --mesh nonplanar.msh", "nonplanar.msh"),
    ("3D: volume elements", "mesh --mesh volume.msh", "volume.msh"),
]

# Inputs that must be accepted (exit 0): the overrides and the tolerated cases, so the refusals cannot be blanket;
# a third element is a text the output must hold (a warning).
ACCEPTED = [
    ("strength above the modulus with --force", "mesh -q modulus_in_gpa.toml --force --set mesh.size=0.005"),
    ("clockwise triangles are turned, not refused", "mesh -q --mesh clockwise.msh"),
    ("a good mesh", "mesh -q --mesh good_square.msh"),
    ("a mesh drawn in millimetres is flagged", "mesh -q --mesh millimetre_square.msh", "drawn in millimetres"),
    ("a mesh realization", "mesh -q --set mesh.seed=3 --set mesh.size=0.005"),
]


def run(rbdem, work, command):
    proc = subprocess.run([rbdem] + command.split(), cwd=work, capture_output=True, text=True, timeout=60)
    return proc.returncode, proc.stdout, proc.stderr


def cell(text):
    return " ".join(text.split()).replace("|", "\\|")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rbdem", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--docs", default=os.path.join(SOURCE, "docs", "bad_inputs.md"))
    # The page documents the full build; a build without deal.II (no `elastic` command, e.g. the sanitizer build)
    # lists other commands in its messages, so it checks the refusals only.
    ap.add_argument("--no-docs", action="store_true", help="check the refusals, not the page")
    args = ap.parse_args()
    rbdem = os.path.abspath(args.rbdem)
    work = os.path.abspath(args.work)
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(os.path.join(work, "folder"))
    for name in os.listdir(DATA):
        shutil.copy(os.path.join(DATA, name), work)
    for name, text in SCENES.items():
        with open(os.path.join(work, name), "w") as f:
            f.write(text)

    failures = []
    rows = []
    for what, command, name in CASES:
        code, out, err = run(rbdem, work, command)
        message = err.strip()
        if message.startswith("rbdem: error: "):
            message = message[len("rbdem: error: "):]
        if code != 2:
            failures.append(f"{what}: `rbdem {command}` exited {code}, expected 2 (bad input)\n{err}")
        if name not in message:
            failures.append(f"{what}: the message does not name `{name}`:\n{err}")
        if "rbdem: run failed" in err or code < 0:
            failures.append(f"{what}: crashed or failed instead of refusing:\n{err}")
        rows.append(f"| {cell(what)} | `rbdem {command}` | {code} | {cell(message)} |")
    for what, command, *expect in ACCEPTED:
        code, out, err = run(rbdem, work, command)
        if code != 0:
            failures.append(f"{what}: `rbdem {command}` exited {code}, expected 0\n{err}")
        for text in expect:
            if text not in out:
                failures.append(f"{what}: `rbdem {command}` does not say '{text}':\n{out}")

    page = (
        "# Bad input and what rbdem says\n\n"
        "Every input below is refused with exit status 2 (bad input) and a message naming the key, option or file\n"
        "and the fix. Generated by `tests/bad_inputs.py`, which the test `BadInputs.RefusedWithExitStatus2` runs;\n"
        "refresh with `RBDEM_UPDATE_DOCS=1 ctest --test-dir build -R BadInputs`. Scene cases run `rbdem mesh`, which\n"
        "resolves the scene exactly as `ucs` and `elastic` do. Likely unit mistakes are refused (a stress written in\n"
        "MPa or GPa: a modulus under 1 MPa, a strength, pressure or stress under 1 kPa; a strength at or above its\n"
        "modulus; a user mesh drawn in millimetres); `--force` runs them anyway. Keys left out of a scene take their defaults\n"
        "(`rbdem --help-scene`), so a missing key is not an error; a missing file or value is. Clockwise triangles in a\n"
        "user mesh are turned counter-clockwise with a note, not refused. See docs/reliability.md.\n\n"
        f"{len(rows)} inputs.\n\n"
        "| input tried | command | exit status | message |\n"
        "|---|---|---:|---|\n" + "\n".join(rows) + "\n"
    )
    generated = os.path.join(work, "bad_inputs.md")
    with open(generated, "w") as f:
        f.write(page)
    if os.environ.get("RBDEM_UPDATE_DOCS"):
        with open(args.docs, "w") as f:
            f.write(page)
        print(f"bad_inputs: wrote {args.docs}")
    try:
        with open(args.docs) as f:
            current = f.read()
    except OSError:
        current = ""
    if current != page and not args.no_docs:
        diff = "".join(difflib.unified_diff(current.splitlines(True), page.splitlines(True), args.docs, generated))
        failures.append(f"{args.docs} differs from the generated table ({generated}):\n{diff}\n"
                        "refresh it: RBDEM_UPDATE_DOCS=1 ctest --test-dir build -R BadInputs")
    for f in failures:
        print("FAIL:", f, file=sys.stderr)
    print(f"bad_inputs: {len(CASES)} bad inputs refused, {len(ACCEPTED)} good ones accepted; "
          f"{len(failures)} failures")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
