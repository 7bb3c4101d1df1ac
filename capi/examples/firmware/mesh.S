/* The baked mesh in flash, aligned as the loader needs (128 bytes); mesh.bin is
 * `raykernel bake`'s output, found on the assembler's include path. */
    .section .rodata.baked_mesh, "a"
    .balign 128
    .global baked_mesh
baked_mesh:
    .incbin "mesh.bin"
baked_mesh_end:
    .balign 4
    .global baked_mesh_len
baked_mesh_len:
    .word baked_mesh_end - baked_mesh
    .section .note.GNU-stack, "", %progbits
