# box-die (paper 001): the die cavity of a 100 × 100 × 60 block, φ10 square end mill, 4 layers of
# 10 mm, engagement threshold 40° → trochoids along the dangerous medial axis first, then the
# offset passes (the wall pass's inside corners rounded by simulation, their rest left to
# finishing); report of engagement before/after and time against the offset-only program under
# the feed model of paper 001 (chip thickness and a constant cutting force: the force of the side
# cut at BOX_DIE_FORCE_AT degrees is the most the tool takes), and with the chip limit alone.
DEMOS += box-die
FILTERS += medial-trochoid
BOX_DIE := $(OUT)/box-die
BOX_DIE_RADIUS ?= 5
BOX_DIE_THRESHOLD ?= 40
BOX_DIE_LAYERS ?= 4
BOX_DIE_LAYER_DEPTH ?= 10
BOX_DIE_SAMPLE ?= 1
BOX_DIE_TROCHOID_RADIUS ?= 2.5
BOX_DIE_FORCE_AT ?= $(BOX_DIE_THRESHOLD)

.PHONY: demo-box-die
demo-box-die: $(BOX_DIE)/program.csv

$(BOX_DIE)/program.csv $(BOX_DIE)/report.json $(BOX_DIE)/trochoids.svg $(BOX_DIE)/offset-only.svg &: data/medial-trochoid/box-die.csv $(RELEASE)/medial-trochoid | $(BOX_DIE)/
	$(RELEASE)/medial-trochoid $< --radius $(BOX_DIE_RADIUS) --threshold $(BOX_DIE_THRESHOLD) \
	  --layers $(BOX_DIE_LAYERS) --layer-depth $(BOX_DIE_LAYER_DEPTH) --sample $(BOX_DIE_SAMPLE) \
	  --trochoid-radius $(BOX_DIE_TROCHOID_RADIUS) --force-at $(BOX_DIE_FORCE_AT) --decimals 4 \
	  --svg $(BOX_DIE)/trochoids.svg --svg-other $(BOX_DIE)/offset-only.svg --report $(BOX_DIE)/report.json -o $(BOX_DIE)/program.csv
