// `gltf-transform prune in.glb out.glb --config js/gltf-transform-animorder/gltf-transform.config.js`
// (the option after the command: the CLI reads it there): the CLI reads, keeps and writes
// ANIMORDER_animated_triangle_orders. The CLI replaces its own extension list by a config's, so
// the list is every extension glTF-Transform knows plus ours: KHR_* ones are kept, not dropped.
import { ALL_EXTENSIONS } from '@gltf-transform/extensions';
import { AnimorderTriangleOrders } from './index.js';

export default { extensions: [...ALL_EXTENSIONS, AnimorderTriangleOrders] };
