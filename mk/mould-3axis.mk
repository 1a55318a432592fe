# mould-3axis: a mould the project generates (scripts/mould-stl.py: a 120 × 80 × 40 block with a
# spherical dish R40 12 deep and a half-pipe R10 with round ends, 123 000 triangles) finished with
# a ball end mill R3 on a 3-axis machine: stylus-trace rasters it with a stylus of the ball's
# radius (one-way lines, MOULD_PICK apart), tool-attitude puts the tips on the fixed vertical axis
# (tip = stylus centre − 3 along z), post-6axis links the lines through the job's safe height and
# checks the program against the stock it has cut and the mould itself (the ball and its holder
# cast along every move), curve-fit-arcs turns the program's G1 runs into arcs in the planes they
# lie in (the raster's are XZ: G18) within MOULD_FIT_TOL, and the fitted program is checked again
# (`post-6axis --check`). The variant confined to the dish (MOULD_CAVITY) has every line start and
# end below the stock top: posted as given (naive-cavity.nc, straight G0s from line to line) the
# same check finds its rapids cutting through uncut stock (naive-cavity-check.json); linked, none.
DEMOS += mould-3axis
FILTERS += stylus-trace tool-attitude post-6axis curve-fit-arcs
MOULD := $(OUT)/mould-3axis
MOULD_STL_STEP ?= 0.4
MOULD_PICK ?= 1
MOULD_CHORD_TOL ?= 0.002
MOULD_FIT_TOL ?= 0.002
MOULD_CAVITY ?= 12,68,12,68
MOULD_MACHINE ?= data/post-6axis/three-axis.json

.PHONY: demo-mould-3axis
demo-mould-3axis: $(MOULD)/mould.ngc $(MOULD)/mould-fit.ngc $(MOULD)/mould-cavity.ngc $(MOULD)/naive-cavity-check.json

$(MOULD)/mould.stl: scripts/mould-stl.py | $(MOULD)/
	python3 scripts/mould-stl.py $@ --step $(MOULD_STL_STEP)

# The job's setup and tool beside the STL, which the setup names.
$(MOULD)/setup.json: data/jobs/mould-3axis.json | $(MOULD)/
	cp $< $@
$(MOULD)/ball-r3.json: data/jobs/ball-r3.json | $(MOULD)/
	cp $< $@

$(MOULD)/cl.csv $(MOULD)/cl.json &: $(MOULD)/mould.stl $(RELEASE)/stylus-trace
	$(RELEASE)/stylus-trace $< --mode scan -r 3 --pick $(MOULD_PICK) --chord-tol $(MOULD_CHORD_TOL) \
	  --report $(MOULD)/cl.json -o $(MOULD)/cl.csv

$(MOULD)/cl-cavity.csv $(MOULD)/cl-cavity.json &: $(MOULD)/mould.stl $(RELEASE)/stylus-trace
	$(RELEASE)/stylus-trace $< --mode scan -r 3 --pick $(MOULD_PICK) --chord-tol $(MOULD_CHORD_TOL) \
	  --region=$(MOULD_CAVITY) --report $(MOULD)/cl-cavity.json -o $(MOULD)/cl-cavity.csv

$(MOULD)/tip.csv: $(MOULD)/cl.csv $(MOULD)/ball-r3.json $(RELEASE)/tool-attitude
	$(RELEASE)/tool-attitude $< --tool $(MOULD)/ball-r3.json --axis 0,0,1 -o $@

$(MOULD)/tip-cavity.csv: $(MOULD)/cl-cavity.csv $(MOULD)/ball-r3.json $(RELEASE)/tool-attitude
	$(RELEASE)/tool-attitude $< --tool $(MOULD)/ball-r3.json --axis 0,0,1 -o $@

$(MOULD)/mould.ngc $(MOULD)/mould.json &: $(MOULD)/tip.csv $(MOULD)/setup.json $(MOULD)/ball-r3.json $(MOULD)/mould.stl $(MOULD_MACHINE) $(RELEASE)/post-6axis
	$(RELEASE)/post-6axis $< --machine $(MOULD_MACHINE) --setup $(MOULD)/setup.json \
	  --report $(MOULD)/mould.json -o $(MOULD)/mould.ngc

$(MOULD)/mould-cavity.ngc $(MOULD)/mould-cavity.json &: $(MOULD)/tip-cavity.csv $(MOULD)/setup.json $(MOULD)/ball-r3.json $(MOULD)/mould.stl $(MOULD_MACHINE) $(RELEASE)/post-6axis
	$(RELEASE)/post-6axis $< --machine $(MOULD_MACHINE) --setup $(MOULD)/setup.json \
	  --report $(MOULD)/mould-cavity.json -o $(MOULD)/mould-cavity.ngc

# The program's G1 runs as arcs, then the same collision check on the fitted program.
$(MOULD)/mould-fit.ngc $(MOULD)/mould-fit.json &: $(MOULD)/mould.ngc $(MOULD)/setup.json $(RELEASE)/curve-fit-arcs $(RELEASE)/post-6axis
	$(RELEASE)/curve-fit-arcs $< --tol $(MOULD_FIT_TOL) --plane auto --report $(MOULD)/mould-fit-arcs.json -o $(MOULD)/mould-fit.ngc
	$(RELEASE)/post-6axis --machine $(MOULD_MACHINE) --setup $(MOULD)/setup.json --check $(MOULD)/mould-fit.ngc > $(MOULD)/mould-fit.json

# The cavity raster posted as given (no setup) and checked: what straight G0s would do.
$(MOULD)/naive-cavity-check.json: $(MOULD)/tip-cavity.csv $(MOULD)/setup.json $(MOULD_MACHINE) $(RELEASE)/post-6axis
	$(RELEASE)/post-6axis $< --machine $(MOULD_MACHINE) --feed 1500 -o $(MOULD)/naive-cavity.nc 2>/dev/null
	$(RELEASE)/post-6axis --machine $(MOULD_MACHINE) --setup $(MOULD)/setup.json --check $(MOULD)/naive-cavity.nc > $@ 2>/dev/null || [ $$? -eq 1 ]
	grep -q '"rapids_into_material": [1-9]' $@
