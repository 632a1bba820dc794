"""How to cite and under which licence (issue 43, item 7): CITATION.cff names the workbench and the paper it reproduces
(Theurich & Krack) as its preferred citation, with the version and licence pyproject.toml states; LICENSE is that
licence's text; the README says both."""
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
TITLE = "Experimental validation of impact energy scattering as concept for mitigating resonant vibrations"


def test_the_citation_file_names_the_workbench_and_the_paper():
    yaml = pytest.importorskip("yaml")
    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text())
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert cff["cff-version"] == "1.2.0" and cff["type"] == "software" and cff["authors"]
    assert cff["version"] == project["version"] and cff["license"] == project["license"]["text"] == "MIT"
    paper = cff["preferred-citation"]
    assert paper["type"] == "article" and paper["title"] == TITLE
    assert [(a["given-names"], a["family-names"]) for a in paper["authors"]] == [("Timo", "Theurich"),
                                                                                ("Malte", "Krack")]
    assert paper in cff["references"]
    assert " ".join(f"*{TITLE}*".split()) in " ".join((ROOT / "README.md").read_text().split())


def test_the_licence_is_the_mit_text_and_the_readme_says_so():
    text = (ROOT / "LICENSE").read_text()
    assert text.startswith("MIT License\n") and "THE SOFTWARE IS PROVIDED \"AS IS\"" in text
    readme = (ROOT / "README.md").read_text()
    assert "Cite: " in readme and "[`CITATION.cff`](CITATION.cff)" in readme and "Licence: MIT, [`LICENSE`](LICENSE)" in readme
