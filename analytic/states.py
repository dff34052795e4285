"""The response states of the layered cavity expansion in words: the paper's Fig. 2 letters
(where the elastic-plastic boundary ``b`` lies; :data:`cavex.analytic.cavity.PAPER_STATES`) and
what each label means for a target's layers (:func:`state_meaning`).

Plain Python, apart from the closed forms (:mod:`cavex.analytic.cavity` loads numba): ``cavex
stress`` spells a state out, and the verification report names the states in its text and
figures, without loading more than they need.
"""


# The paper's Fig. 2 states by the number of layers around the cavity ({0} = the wall layer):
# where the elastic-plastic boundary b lies (cavex.analytic.cavity.PAPER_STATES).
STATE_POSITIONS = {
    3: dict(zip("abcde", ("inside {0}", "at the {0}|{1} interface ({1} elastic)", "inside {1}",
                          "at the {1}|{2} interface ({2} elastic)", "inside {2}"), strict=True)),
    2: dict(zip("fgh", ("inside {0}", "at the {0}|{1} interface ({1} elastic)", "inside {1}"),
                strict=True)),
}
STATE_GROUPS = {3: "a-e", 2: "f-h"}
STATE_SUFFIXES = {"island": "a layer between plastic ones stays elastic",
                  "free": "the plastic zone reaches the free surface"}


def state_meaning(label, names, short=False):
    """Plain-language meaning of a response-state label for a target with layer ``names``.

    The letters a-e are the states with three layers around the cavity (the last three),
    f-h with two, ``single`` with one (:data:`STATE_POSITIONS`). ``short``: without the list
    of the layers around the cavity.
    """
    base, *suffixes = str(label).split("+")
    count = next((n for n, states in STATE_POSITIONS.items() if base in states), None)
    if count is not None and len(names) >= count:
        around = list(names[-count:])
        where = STATE_POSITIONS[count][base].format(*around)
        text = (f"plastic zone ends {where}" if short else f"{' + '.join(around)} around the "
                f"cavity; the plastic zone (radius b) ends {where}")
    elif base == "single":
        text = f"plastic zone in {names[-1]}" if short else \
            f"{names[-1]} alone around the cavity; the plastic zone (radius b) lies in it"
    elif base == "elastic":
        text = "nothing yields (no plastic zone)"
    else:
        text = (f"plastic zone ends at position code {base[1:]} (more layers than the "
                "paper's figure)")
    return "; ".join([text] + [STATE_SUFFIXES.get(s, s) for s in suffixes])
