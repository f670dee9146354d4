"""Draw every catalogue case's diagram (counted by the flow) into docs/images/case_<name>.png
and print each case's figures as JSON (the gallery of docs/workbench.md).

Arguments: case names, to draw only those. Run from the repository's root.
"""

import json
import sys
import time

from chargedesign.model.catalogue import catalogue_cases
from chargedesign.topology.case_map import diagram_refusal
from chargedesign.topology.diagram import bifurcation_diagram


def main(only: set[str]) -> list[dict]:
    rows = []
    for case in catalogue_cases():
        if only and case.name not in only:
            continue
        refusal = diagram_refusal(case)
        if refusal:
            rows.append({"case": case.name, "refused": refusal})
            continue
        start = time.perf_counter()
        # Euler's energies on I3 = 0 have no scale (V = l = 0): the command asks for --h-range
        h_range = (0.0, 1.0) if case.name == "euler" else None
        try:
            # every entry through the stages of a case without closed form (the theorem's
            # entries too: the gallery compares them on one footing)
            diagram = bifurcation_diagram(case, h_range, level=case.level or 0, closed_form=False)
        except Exception as exc:  # the gallery records what happened
            rows.append({"case": case.name, "error": f"{type(exc).__name__}: {exc}"})
            continue
        seconds = time.perf_counter() - start
        name = case.name.replace("-", "_")
        diagram.plot().savefig(f"docs/images/case_{name}.png", dpi=90)
        summary = diagram.to_dict()
        rows.append(
            {
                "case": case.name,
                "level": summary["level"],
                "seconds": round(seconds, 1),
                "branches": [(b["name"], b["types"]) for b in summary["branches"]],
                "tori": [c["tori"] for c in summary["chambers"]],
            }
        )
        print(json.dumps(rows[-1]), file=sys.stderr, flush=True)
    return rows


if __name__ == "__main__":
    print(json.dumps(main(set(sys.argv[1:])), indent=1))
