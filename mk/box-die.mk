# box-die (paper 001): the die cavity of a 100 × 100 × 60 block, φ10 square end mill, 4 layers of
# 10 mm, engagement threshold 40° → trochoids along the dangerous medial axis first, then the
# offset passes (the wall pass's inside corners rounded by simulation, their rest left to
# finishing); report of engagement before/after and time against the offset-only program under
# the feed model of paper 001 (chip thickness and a constant cutting force: the force of the side
# cut at BOX_DIE_FORCE_AT degrees is the most the tool takes), and with the chip limit alone.
# The job's setup (data/jobs/box-die.json: the block, the cavity's walls down to its floor at
# z = 20, the φ10 tool, heights, a 3° ramp) gives medial-trochoid the tool radius and the layers
# (60 → 20 in steps of at most BOX_DIE_LAYER_DEPTH), and post-6axis the links and the collision
# check of program.ngc.
DEMOS += box-die
FILTERS += medial-trochoid post-6axis
BOX_DIE := $(OUT)/box-die
BOX_DIE_SETUP ?= data/jobs/box-die.json
BOX_DIE_MACHINE ?= data/post-6axis/three-axis.json
BOX_DIE_THRESHOLD ?= 40
BOX_DIE_LAYER_DEPTH ?= 10
BOX_DIE_SAMPLE ?= 1
BOX_DIE_TROCHOID_RADIUS ?= 2.5
BOX_DIE_FORCE_AT ?= $(BOX_DIE_THRESHOLD)

.PHONY: demo-box-die
demo-box-die: $(BOX_DIE)/program.csv $(BOX_DIE)/program.ngc $(BOX_DIE)/adaptive.ngc

$(BOX_DIE)/program.csv $(BOX_DIE)/report.json $(BOX_DIE)/trochoids.svg $(BOX_DIE)/offset-only.svg &: data/medial-trochoid/box-die.csv $(BOX_DIE_SETUP) $(RELEASE)/medial-trochoid | $(BOX_DIE)/
	$(RELEASE)/medial-trochoid $< --setup $(BOX_DIE_SETUP) --threshold $(BOX_DIE_THRESHOLD) \
	  --layer-depth $(BOX_DIE_LAYER_DEPTH) --sample $(BOX_DIE_SAMPLE) \
	  --trochoid-radius $(BOX_DIE_TROCHOID_RADIUS) --force-at $(BOX_DIE_FORCE_AT) --decimals 4 \
	  --svg $(BOX_DIE)/trochoids.svg --svg-other $(BOX_DIE)/offset-only.svg --report $(BOX_DIE)/report.json -o $(BOX_DIE)/program.csv

# The trochoids-first program for the 3-axis machine: every chain linked (retract to the safe
# height, traverse, rapid to 1 mm over what the earlier cuts left, 3° ramp along the pass), the
# written program checked against the material left and the cavity's walls before delivery;
# program.svg is the program read back (rapids, ramps, leads, cuts; arcs as arcs).
$(BOX_DIE)/program.ngc $(BOX_DIE)/program.json $(BOX_DIE)/program.svg &: $(BOX_DIE)/program.csv $(BOX_DIE_SETUP) $(BOX_DIE_MACHINE) $(RELEASE)/post-6axis
	$(RELEASE)/post-6axis $< --machine $(BOX_DIE_MACHINE) --setup $(BOX_DIE_SETUP) \
	  --svg $(BOX_DIE)/program.svg --report $(BOX_DIE)/program.json -o $(BOX_DIE)/program.ngc

# Beside the paper's: the adaptive program (--strategy adaptive, the same target, layers, sample,
# force limit and 4 decimals: passes whose every step holds the engagement at the target by the
# exact simulation), posted for the same machine with the same links and collision check.
$(BOX_DIE)/adaptive.csv $(BOX_DIE)/adaptive-report.json $(BOX_DIE)/adaptive-plan.svg &: data/medial-trochoid/box-die.csv $(BOX_DIE_SETUP) $(RELEASE)/medial-trochoid | $(BOX_DIE)/
	$(RELEASE)/medial-trochoid $< --strategy adaptive --setup $(BOX_DIE_SETUP) --threshold $(BOX_DIE_THRESHOLD) \
	  --layer-depth $(BOX_DIE_LAYER_DEPTH) --sample $(BOX_DIE_SAMPLE) --force-at $(BOX_DIE_FORCE_AT) --decimals 4 \
	  --svg $(BOX_DIE)/adaptive-plan.svg --report $(BOX_DIE)/adaptive-report.json -o $(BOX_DIE)/adaptive.csv

$(BOX_DIE)/adaptive.ngc $(BOX_DIE)/adaptive.json $(BOX_DIE)/adaptive.svg &: $(BOX_DIE)/adaptive.csv $(BOX_DIE_SETUP) $(BOX_DIE_MACHINE) $(RELEASE)/post-6axis
	$(RELEASE)/post-6axis $< --machine $(BOX_DIE_MACHINE) --setup $(BOX_DIE_SETUP) \
	  --svg $(BOX_DIE)/adaptive.svg --report $(BOX_DIE)/adaptive.json -o $(BOX_DIE)/adaptive.ngc
