# Two entry points for a fresh machine: `make test` and `make demo`.
# Both create .venv and install the package into it; nothing is installed by hand.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: test demo bench bench-ycb venv clean

venv: $(STAMP)

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip
	$(BIN)/pip install --quiet -e '.[test,sim,cluster,ycb,ros]'
	touch $(STAMP)

test: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python -m pytest -q

demo: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python tools/demo.py demo-output

# The thesis's grasping experiment (Table 4.4) in simulation: 5 objects x 20 trials x 4 planners,
# plus the ablation steps from paper to default.
bench: $(STAMP)
	MPLBACKEND=Agg $(BIN)/contourgrasp bench --objects can,case,bottle,stone1,stone2 --trials 20 \
		--planners paper,default,centroid-principal-axis,random --ablation --out bench-output

# The YCB object set: the fixed train and test splits, 10 trials per object, on every core,
# with the 3-D hand's ablation: the 2-D planner, + finger bodies, + grasp height, = default.
bench-ycb: $(STAMP)
	MPLBACKEND=Agg $(BIN)/contourgrasp bench --objects ycb-train,ycb-test --trials 10 \
		--planners paper,paper+grid+quality,paper+grid+quality+bodies,paper+grid+quality+bodies+height,paper+grid+quality+bodies+height+small+closing,paper+grid+quality+bodies+height+small+closing+balance,default,centroid-principal-axis,random \
		--workers $$(nproc) --out bench-ycb-output

clean:
	rm -rf $(VENV) demo-output bench-output bench-ycb-output .pytest_cache
